"""What `adfkit ros` serves, decided without ROS: AMBF's names, topics and joint order
(adfkit/ros/objects.py against afFramework.cpp's rules)."""

from __future__ import annotations

import pytest
from conftest import ROOT

pytest.importorskip("pybullet")

from adfkit.adf import load_scene
from adfkit.ros.objects import ros_objects, topic_of
from adfkit.runner import Options, open_world
from adfkit.runner.psm import ARM_JOINTS, JAW_JOINTS

SAMPLE = ROOT / "sample_scenes" / "suturing"
ARM = [j.replace(" ", "") for j in ARM_JOINTS + JAW_JOINTS]  # AMBF's names: spaces removed


def _served(launch, indices=None):
    world = open_world(load_scene(launch, indices, []), Options(control_substeps=1), engine="pybullet")
    try:
        return {o.topic: o for o in ros_objects(world)}
    finally:
        world.close()


def _psm_copy(tmp_path, joints: list[str], passive: str | None = None):
    """The bundled psm1 alone, its `joints:` list in the given order (and one joint passive)."""
    import shutil

    shutil.copytree(SAMPLE / "psm" / "meshes", tmp_path / "meshes")
    text = (SAMPLE / "psm" / "psm1.yaml").read_text()
    head, rest = text.split("joints:\n", 1)
    listed = [line for line in rest.splitlines() if line.startswith("- JOINT ")]
    assert sorted(listed) == sorted(f"- JOINT {j}" for j in joints)
    rest = rest.replace("\n".join(listed), "\n".join(f"- JOINT {j}" for j in joints), 1)
    text = head + "joints:\n" + rest
    if passive:
        at = text.index(f"JOINT {passive}:\n")
        end = text.index("passive: false", at)
        text = text[:end] + "passive: true" + text[end + len("passive: false") :]
    (tmp_path / "psm1.yaml").write_text(text)
    return tmp_path / "psm1.yaml"


def test_the_bundled_scene_is_served_under_ambf_names():
    served = _served(SAMPLE / "launch.yaml")
    base = served["/ambf/env/psm1/baselinksimple"]  # spaces removed from `base link simple`
    assert base.kind == "rigid_body" and base.identifier == "/ambf/env/psm1/BODY base link simple"
    assert [j.name for j in base.joints] == ARM  # the challenge's joint indices 0..7
    assert all(j.art is not None for j in base.joints)
    assert served["/ambf/env/ghosts/psm1/Sensor0"].kind == "sensor"
    assert served["/ambf/env/ghosts/psm1/Actuator0"].kind == "actuator"
    assert served["/ambf/env/cameras/cameraL"].kind == "camera"
    assert served["/ambf/env/phantom/Needle"].kind == "rigid_body"
    # a link's list holds the joints below it only
    assert [j.name for j in served["/ambf/env/psm1/toolyawlinksimple"].joints] == ARM[6:]
    assert topic_of("/ambf/env//psm1", "x") == "/ambf/env/psm1/x"


def test_joint_order_follows_ambf_creation_order(tmp_path):
    """AMBF numbers a body's joints as addChildBodyJointPair meets them, in the file's `joints:`
    order: the corpus PSM's definitions in alphabetical order give this order (worked through
    by hand from afFramework.cpp), not the arm's; a passive joint is left out."""
    alphabetical = sorted(ARM_JOINTS + JAW_JOINTS)
    launch = _psm_copy(tmp_path, alphabetical)
    base = next(o for o in _served(launch).values() if o.name == "baselinksimple")
    assert [j.name for j in base.joints] == [
        "baselink-yawlink",
        "maininsertionlink-toolrolllink",
        "pitchendlink-maininsertionlink",
        "toolpitchlink-toolyawlink",
        "toolrolllink-toolpitchlink",
        "toolyawlink-toolgripper1link",
        "toolyawlink-toolgripper2link",
        "yawlink-pitchbacklink",
    ]


def test_a_passive_joint_is_not_served(tmp_path):
    order, names = list(ARM), list(ARM_JOINTS + JAW_JOINTS)
    (tmp_path / "a").mkdir()
    launch = _psm_copy(tmp_path / "a", names, passive="tool yaw link-tool gripper1 link")
    base = next(o for o in _served(launch).values() if o.name == "baselinksimple")
    assert [j.name for j in base.joints] == [n for n in order if n != "toolyawlink-toolgripper1link"]


def test_the_watchdog_ends_step_throttling_after_its_time_out():
    """AMBF's world watchdog: a throttled world waits for the client's step clock while the client
    keeps sending world commands; once none came for the time out (0.5 s, AMBF's, or what
    `adfkit ros --watchdog` gives) it runs free again. Decided by the world's handler alone."""
    import types

    from adfkit.ros.bridge import WATCHDOG_S, WorldHandler

    for timeout in (WATCHDOG_S, 2.0):
        h = object.__new__(WorldHandler)  # the rule, without a ROS master
        h.bridge = types.SimpleNamespace(watchdog_s=timeout)
        h.heard, h.throttle, h.allowed = 100.0, True, 0
        assert not h.may_step(100.0 + 0.9 * timeout)  # fed: held until the clock grants a step
        h.allowed = 1
        assert h.may_step(100.0 + 0.9 * timeout) and h.throttle
        h.allowed = 0
        assert h.may_step(100.0 + 1.1 * timeout) and not h.throttle  # silent past the time out: free
    assert WATCHDOG_S == 0.5


def test_adfkit_ros_refuses_a_watchdog_that_is_no_time_out(capsys):
    from adfkit.cli import main

    assert main(["ros", str(SAMPLE), "--watchdog", "0"]) == 2
    assert "--watchdog 0 is not a time out" in capsys.readouterr().err
