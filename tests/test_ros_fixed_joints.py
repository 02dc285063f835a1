"""A body whose joint list (AMBF's, by index) holds a fixed joint inside the multibody, as the
corpus's puzzle2 does: a command on that index (an ambf_client script that sets every joint,
or the zero efforts ambf_client pads the list with before the index it sets) is one AMBF leaves
alone. Before, `adfkit ros` stopped on it (ValueError: not a revolute, prismatic or spring joint
of an articulation); now it is ignored, said once, and the hinge beside it still moves."""

from __future__ import annotations

import pytest
import ros_support as rs

pytest.importorskip("pybullet")

MODEL = """namespace: /ambf/env/
bodies: [BODY base, BODY arm, BODY tip]
joints: [JOINT base-arm, JOINT arm-tip]
BODY base:
  name: base
  mass: 0.0
  location: {position: {x: 0.0, y: 0.0, z: 0.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  collision shape: BOX
  collision geometry: {x: 0.1, y: 0.1, z: 0.1}
  shape: BOX
  geometry: {x: 0.1, y: 0.1, z: 0.1}
BODY arm:
  name: arm
  mass: 1.0
  inertia: {ix: 1.0e-3, iy: 1.0e-3, iz: 1.0e-3}
  location: {position: {x: 0.1, y: 0.0, z: 0.2}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  collision shape: BOX
  collision geometry: {x: 0.2, y: 0.05, z: 0.05}
  shape: BOX
  geometry: {x: 0.2, y: 0.05, z: 0.05}
BODY tip:
  name: tip
  mass: 0.1
  inertia: {ix: 1.0e-4, iy: 1.0e-4, iz: 1.0e-4}
  location: {position: {x: 0.25, y: 0.0, z: 0.2}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  collision shape: BOX
  collision geometry: {x: 0.05, y: 0.05, z: 0.05}
  shape: BOX
  geometry: {x: 0.05, y: 0.05, z: 0.05}
JOINT base-arm:
  name: base-arm
  parent: BODY base
  child: BODY arm
  parent axis: {x: 0.0, y: 0.0, z: 1.0}
  parent pivot: {x: 0.0, y: 0.0, z: 0.2}
  child axis: {x: 0.0, y: 0.0, z: 1.0}
  child pivot: {x: -0.1, y: 0.0, z: 0.0}
  joint limits: {low: -1.5, high: 1.5}
  type: revolute
JOINT arm-tip:
  name: arm-tip
  parent: BODY arm
  child: BODY tip
  parent axis: {x: 0.0, y: 0.0, z: 1.0}
  parent pivot: {x: 0.15, y: 0.0, z: 0.0}
  child axis: {x: 0.0, y: 0.0, z: 1.0}
  child pivot: {x: 0.0, y: 0.0, z: 0.0}
  type: fixed
"""


def test_commands_on_a_fixed_joint_are_ignored_and_the_hinge_still_moves(tmp_path):
    rs.require_client()
    paths = rs.ambf_client(tmp_path / "ambf")
    model = tmp_path / "arm.yaml"
    model.write_text(MODEL)
    out, alive, err = rs.served(
        model,
        lambda master: rs.run_client(
            master,
            paths,
            """
            import json, time
            from ambf_client import Client
            c = Client("t_fixed"); c.connect(); time.sleep(0.3)
            base = c.get_obj_handle("/ambf/env/base"); time.sleep(0.5)
            names = list(base.get_joint_names())
            for k in range(len(names)):  # every joint of the list, the fixed one too
                base.set_joint_vel(k, 0.2)
            time.sleep(0.5)
            base.set_joint_effort(1, 0.5); time.sleep(0.3)
            base.set_joint_pos(0, 0.4)
            t = time.time()
            while time.time() - t < 10 and abs(base.get_joint_pos(0) - 0.4) > 2e-3:
                time.sleep(0.05)
            print(json.dumps({"names": names, "q": base.get_all_joint_pos()}))
            """,
        ),
    )
    assert alive and "Traceback" not in err, err
    assert out["names"] == ["base-arm", "arm-tip"]
    assert abs(out["q"][0] - 0.4) < 5e-3
    assert "joint arm-tip is a fixed joint, which AMBF moves by no velocity command; ignored" in err
    assert "joint arm-tip is a fixed joint, which AMBF moves by no effort command; ignored" in err


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_twist_moves_a_static_multibody_root_with_its_links(tmp_path, engine):
    """AMBF moves a static body by a twist command, v·dt a step (its COM frame), whatever hangs
    from it following through the joints. Before, the root of a multibody (the arm's base here,
    a PSM's base in the suturing scene) did not move in the MuJoCo engine, which said that a
    twist moves free bodies only (PyBullet moved it by the base's velocity)."""
    pytest.importorskip(engine)
    rs.require_client()
    paths = rs.ambf_client(tmp_path / "ambf")
    model = tmp_path / "arm.yaml"
    model.write_text(MODEL)
    out, _, err = rs.served(
        model,
        lambda master: rs.run_client(
            master,
            paths,
            """
            import json, time
            from ambf_client import Client
            c = Client("t_twist"); c.connect(); time.sleep(0.3)
            base = c.get_obj_handle("/ambf/env/base"); tip = c.get_obj_handle("/ambf/env/tip")
            w = c.get_world_handle(); time.sleep(0.5)
            def pos(h):
                p = h.get_pos(); return [p.x, p.y, p.z]
            b0, t0, s0 = pos(base), pos(tip), w._state.sim_step
            while w._state.sim_step - s0 < 1000:  # 1 s of simulated time at 0.05 m/s along y
                base.set_linear_vel(0.0, 0.05, 0.0); time.sleep(0.02)
            base.set_linear_vel(0.0, 0.0, 0.0); time.sleep(0.3)
            print(json.dumps({"b0": b0, "t0": t0, "b1": pos(base), "t1": pos(tip),
                              "steps": w._state.sim_step - s0}))
            """,
        ),
        "--engine",
        engine,
    )
    assert "Traceback" not in err, err
    moved = out["b1"][1] - out["b0"][1]
    assert 0.045 < moved < 0.07, out  # 0.05 m/s for the ~1 s of steps the commands held
    assert abs(out["b1"][0] - out["b0"][0]) < 1e-3 and abs(out["b1"][2] - out["b0"][2]) < 1e-3
    assert abs((out["t1"][1] - out["t0"][1]) - moved) < 5e-3  # the arm came along
