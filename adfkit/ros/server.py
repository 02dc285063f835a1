"""`adfkit ros`: a scene played by the runner and served over ROS as AMBF serves it.

One loop on one thread steps the world one physics step at a time (``--rate`` steps a second,
dt = 1/rate as AMBF's ``-p`` with ``-t``): apply the held commands, step, publish what is due.
Paced to real time, or, while a client throttles the world (``WorldCmd.enable_step_throttling``),
a step each time the client's step clock grants one, as fast as it asks."""

from __future__ import annotations

import os
import threading
import time
from pathlib import Path

from ..diagnostics import AdfError, error

BEHIND_S = 0.1  # further behind real time than this and pacing starts again from now


def check_master(uri: str) -> None:
    """A clear error (not a hang) when no ROS master answers at ``uri``."""
    import rosgraph

    if not rosgraph.Master("/adfkit_ros", master_uri=uri).is_online():
        raise AdfError(
            error(
                "ros-master",
                f"no ROS master at {uri}",
                None,
                "start one (`roscore`, or `rosmaster --core -p PORT`), or give its address with --master",
            )
        )


class RosServer:
    def __init__(
        self,
        scene_path: Path,
        indices,
        engine: str = "pybullet",
        rate: float = 1000.0,
        master: str | None = None,
        crtk: bool = True,
        teleop: list[str] | None = None,
        images: bool = True,
        log=print,
        solver_iterations: int = 10,
        watchdog_s: float = 0.5,
    ) -> None:
        self.scene_path, self.indices, self.engine, self.rate = Path(scene_path), indices, engine, float(rate)
        self.master = master or os.environ.get("ROS_MASTER_URI") or "http://localhost:11311"
        self.crtk_on, self.teleop_specs, self.images_on, self.log = crtk, list(teleop or []), images, log
        self.solver_iterations, self.watchdog_s = solver_iterations, watchdog_s
        self.stop = threading.Event()
        self.world = self.bridge = self.crtk = None
        self.teleops: list = []
        self.streams: list = []
        self.snapshot = None
        self.steps_run = 0

    # ---- set-up ---------------------------------------------------------------------------
    def start(self) -> None:
        from . import msggen
        from .env import import_ros

        rospy = import_ros()
        os.environ["ROS_MASTER_URI"] = self.master
        check_master(self.master)
        msggen.ensure()
        import ambf_msgs.msg as msgs

        self.world = self._make_world()
        rospy.init_node("ambf_comm_node", anonymous=True, disable_signals=True)
        self.rospy = rospy
        from .bridge import Bridge, CameraHandler
        from .images import GRAPHICS_HZ, CameraStream

        self.bridge = Bridge(self.world, rospy, msgs, log=self.log, watchdog_s=self.watchdog_s)
        self.snapshot = self.world.save_state() if hasattr(self.world, "save_state") else None
        if self.images_on:
            self.streams = [
                CameraStream(self.bridge, h)
                for h in self.bridge.handlers
                if isinstance(h, CameraHandler) and (h.cams[0].camera.publish_image or h.cams[0].camera.publish_depth)
            ]
            if self.streams:
                self.bridge.graphics_hz = GRAPHICS_HZ
        if self.crtk_on or self.teleop_specs:  # teleoperation drives the PSMs through their CRTK side
            from .crtk import Crtk

            self.crtk = Crtk(self.bridge, log=self.log)
        if self.teleop_specs:
            from .teleop import make_teleops

            self.teleops = make_teleops(self.bridge, self.crtk, self.teleop_specs)
        self.bridge.world_handler.grant = threading.Event()

    def _make_world(self):
        from ..adf import load_scene
        from ..runner import open_world
        from ..runner.options import Options

        scene = load_scene(self.scene_path, self.indices, [])
        # AMBF's dt is 1 ms (1/rate above 1 kHz); a loop slower than 1 kHz takes several 1 ms steps
        substeps = max(1, round(1000.0 / self.rate))
        opt = Options(
            physics_hz=max(self.rate, 1000.0),
            control_substeps=substeps,
            renderer="auto",
            solver_iterations=self.solver_iterations,
        )
        return open_world(scene, opt, engine=self.engine)

    def summary(self) -> str:
        kinds: dict[str, int] = {}
        for o in self.bridge.objects:
            kinds[o.kind] = kinds.get(o.kind, 0) + 1
        plural = {"rigid_body": "rigid bodies"}
        what = ", ".join(f"{n} {plural.get(k, k + 's') if n > 1 else k.replace('_', ' ')}" for k, n in kinds.items())
        return f"{what}; world {self.bridge.world_handler.topic}"

    # ---- the loop -------------------------------------------------------------------------
    def reset(self) -> None:
        """World/Command/Reset: every body and joint back where the scene put them, grasps
        released; the clock runs on (AMBF's sim_step does not go back)."""
        w = self.world
        steps = w.steps
        if self.snapshot is not None:
            w.restore_state(self.snapshot)
        else:  # an engine without snapshots: the world built again
            new = self._make_world()
            new.adopt(w)
            w.close()
            self.world = w = new
            self.bridge.rebind(new)
            if self.crtk is not None:
                self.crtk.rebind(new)
        w.steps, w.sim_time = steps, steps * w.dt

    def run(self, seconds: float | None = None) -> None:
        """Serve until stopped (Ctrl-C, rospy shut down) or ``seconds`` of wall time."""
        wh = self.bridge.world_handler
        period = self.world.dt * self.world.opt.control_substeps
        t_end = time.monotonic() + seconds if seconds else None
        next_t = time.monotonic()
        measured, window_t, window_n = self.rate, time.monotonic(), 0
        while not self.stop.is_set() and not self.rospy.is_shutdown():
            now = time.monotonic()
            if t_end is not None and now >= t_end:
                break
            if wh.reset_asked or wh.reset_bodies_asked:
                wh.reset_asked = wh.reset_bodies_asked = False
                self.reset()
            if not wh.may_step(now):  # throttled by the client: wait for its step clock
                self.bridge.publish(measured)
                wh.grant.clear()
                wh.grant.wait(0.002)
                next_t = time.monotonic()
                continue
            self.bridge.apply()
            if self.crtk is not None:
                self.crtk.apply()
            for t in self.teleops:
                t.apply()
            self.world.step(1)
            wh.stepped()
            self.steps_run += 1
            self.bridge.steps += 1
            window_n += 1
            if now - window_t >= 1.0:
                measured, window_t, window_n = window_n / (now - window_t), now, 0
            self.bridge.publish(measured)
            if self.crtk is not None:
                self.crtk.publish()
            for s in self.streams:
                s.publish()
            if wh.throttle:
                next_t = time.monotonic()
                continue
            next_t += period
            wait = next_t - time.monotonic()
            if wait > 0:
                time.sleep(wait)
            elif wait < -BEHIND_S:
                next_t = time.monotonic()

    def close(self) -> None:
        if self.bridge is not None:
            self.bridge.close()
        if self.world is not None:
            self.world.close()
        rospy = getattr(self, "rospy", None)
        if rospy is not None and not rospy.is_shutdown():
            rospy.signal_shutdown("adfkit ros stopped")
