"""The scripted suture driven through ROS as it is played in-process (slow).

In-process, the suture of pair 1 on the bundled scene is played and every command its planner
gives is recorded per control step: both PSMs' joint targets (arm and jaw), the grasp and the
release, the seeded push on the needle. Then `adfkit ros` serves the same scene, stepped by the
client (AMBF's step throttling, one 4 ms control step per step-clock toggle), and AMBF's
unmodified ambf_client sends those commands through ROS: set_joint_pos on each PSM's base, the
actuator's actuate("Needle") / deactuate, a wrench on the needle. The needle through ROS follows
the needle in-process step for step, and ends where it ended: through Entry1 and out of Exit1.

What ROS cannot carry is named: the planner's collision filter between the two arms (a task's
choice inside the world, no AMBF topic sets it) is left out on both sides."""

from __future__ import annotations

import json

import numpy as np
import pytest
import ros_support as rs

pytest.importorskip("pybullet")
pytestmark = pytest.mark.slow

PAIRS = [1]


def record_in_process(tmp_path):
    """(commands per control step, needle positions per step, the episode's metrics)."""
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world
    from adfkit.tasks import suture as suture_mod
    from adfkit.tasks.episode import SOLVER_ITERATIONS
    from adfkit.tasks.metrics import SutureObserver

    world = open_world(load_scene(rs.SAMPLE, None, []), Options(solver_iterations=SOLVER_ITERATIONS))
    world.set_collision = lambda a, b, enabled: None  # ROS has no topic for it: off on both sides
    try:
        task = suture_mod.SutureTask(world, PAIRS, seed=0)
        obs = SutureObserver(task)
        arts = {name: psm.art for name, psm in task.psms.items()}
        events: list = []
        real_actuate, real_release = world.actuate, world.release

        inside = [False]  # the world's actuate releases first: that release is not the planner's

        def arm_of(act) -> str:
            return next(n for n in arts if f"/{n}/" in act.key or f"/{n}/" in act.parent.key)

        def actuate(act, body):
            events.append(("actuate", arm_of(act)))
            inside[0] = True
            try:
                real_actuate(act, body)
            finally:
                inside[0] = False

        def release(act):
            if not inside[0]:
                events.append(("release", arm_of(act)))
            real_release(act)

        world.actuate, world.release = actuate, release
        needle = task.needle
        real_force = needle.force
        pushes: list = []

        stepping = [False]  # forces the world applies itself in a step (the holes' friction) are not commands

        def force(f, at):
            if not stepping[0]:
                pushes.append((list(f), list(at), list(needle.com_position())))
            real_force(f, at)

        needle.force = force
        steps, trail = [], []
        for _phase in task.steps():
            steps.append(
                {
                    "targets": {n: [float(v) for v in a.targets] for n, a in arts.items()},
                    "events": list(events),
                    "push": pushes[-1] if pushes else None,
                }
            )
            events.clear()
            pushes.clear()
            stepping[0] = True
            world.step(1)
            stepping[0] = False
            obs.observe()
            trail.append([float(v) for v in needle.world_matrix()[:3, 3]])
        metrics = obs.metrics(0.0, None)
    finally:
        world.close()
    return steps, np.array(trail), metrics


REPLAY = """
import json, sys, time
import numpy as np
from ambf_client import Client
steps = json.load(open(sys.argv[1]))
c = Client("suture_replay"); c.connect(); time.sleep(0.5)
bases = {n: c.get_obj_handle(n + "/baselink") for n in ("psm1", "psm2")}
acts = {n: c.get_obj_handle(n + "/Actuator0") for n in ("psm1", "psm2")}
needle = c.get_obj_handle("Needle")
w = c.get_world_handle()
time.sleep(0.5)
w.enable_throttling(True); w.set_num_step_skips(1)
w.update(); time.sleep(0.2)  # throttled from here (the first toggle lets one step through)
w.reset(); time.sleep(0.2)  # back to the state the scene starts in (within the 0.5 s world watchdog)
start = w._state.sim_step
trail = []
for k, s in enumerate(steps):
    for n, q in s["targets"].items():
        for i, v in enumerate(q):
            bases[n].set_joint_pos(i, v)
        bases[n].run_publisher()
    for kind, n in s["events"]:
        acts[n].actuate("Needle") if kind == "actuate" else acts[n].deactuate()
        acts[n].run_publisher()
    if s["push"] is not None:
        f, at, com = (np.array(x) for x in s["push"])
        t = np.cross(at - com, f)
        needle.wrench_command(*f, *t)
    else:
        needle.wrench_command(0, 0, 0, 0, 0, 0)
    needle.run_publisher()
    time.sleep(0.002)  # the commands reach the server before the step clock
    target = start + k + 1  # one loop step (four 1 ms physics steps at --rate 250) a toggle
    w.update()
    t0 = time.time()
    while needle._state.sim_step < target and time.time() - t0 < 5:
        time.sleep(0.0002)
    p = needle.get_pos()
    trail.append([p.x, p.y, p.z])
print(json.dumps({"trail": trail}))
"""


def test_the_scripted_suture_through_ros_follows_it_in_process(tmp_path):
    rs.require_client()
    steps, trail_in, metrics = record_in_process(tmp_path)
    assert metrics["all_passed"], metrics.get("failure")  # in-process, with the arms' filter off
    (tmp_path / "steps.json").write_text(json.dumps(steps))
    master = rs.Master()
    try:
        paths = rs.ambf_client(tmp_path / "ambf")
        server = rs.Server(master, rs.SAMPLE, "--rate", "250", "--solver-iterations", "50", "--no-crtk")
        try:
            script = tmp_path / "replay.py"
            script.write_text(REPLAY)
            import subprocess
            import sys

            done = subprocess.run(
                [
                    sys.executable,
                    "-m",
                    "adfkit.ros.pyrun",
                    *[f"--path={p}" for p in paths],
                    str(script),
                    str(tmp_path / "steps.json"),
                ],
                capture_output=True,
                text=True,
                timeout=3000,
                env=master.env,
            )
            line = next((x for x in done.stdout.splitlines() if x.startswith("{")), None)
            assert line is not None, done.stdout[-2000:] + done.stderr[-2000:]
            trail_ros = np.array(json.loads(line)["trail"])
        finally:
            err = server.close()
        assert "Traceback" not in err, err
    finally:
        master.close()
    assert trail_ros.shape == trail_in.shape
    gap = np.linalg.norm(trail_ros - trail_in, axis=1)
    np.save(tmp_path / "trails.npy", np.stack([trail_in, trail_ros]))
    print(f"needle through ROS vs in-process: max {gap.max() * 1000:.3f} mm, final {gap[-1] * 1000:.3f} mm")
    assert gap.max() < 3e-3 and gap[-1] < 2e-3
