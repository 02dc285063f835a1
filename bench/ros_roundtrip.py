"""Command round trip through `adfkit ros` at 1 kHz: a client sends a pose command for a static
body every millisecond (RigidBodyCmd, TYPE_POSITION, a new x each time), and times each until the
body's State shows that x: publish, the server's next loop step applies it, steps, publishes,
the client receives. Goal: < 2 ms. Prints the median, 90th and 99th percentiles per scene, the
share of commands seen, and the server's loop rate (WorldState.dynamic_loop_freq).

Scenes: a single static box (the bridge alone) and the bundled suturing scene (70 bodies).
Needs ROS 1 (make ros). A shared box's load shows in the figures: run it twice.

    python bench/ros_roundtrip.py [--seconds 3]
"""

from __future__ import annotations

import argparse
import os
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

BOX = """namespace: /ambf/env/
bodies: [BODY marker]
BODY marker:
  name: marker
  mass: 0.0
  location: {position: {x: 0.0, y: 0.0, z: 0.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  collision shape: BOX
  collision geometry: {x: 0.01, y: 0.01, z: 0.01}
"""


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def measure(rospy, msgs, topic: str, seconds: float) -> dict:
    sent: dict[int, float] = {}
    lat: list[float] = []
    rate = {"hz": 0}

    def on_state(m) -> None:
        k = int(round(m.pose.position.x * 1e4))
        t = sent.pop(k, None)
        if t is not None:
            lat.append(time.perf_counter() - t)

    def on_world(m) -> None:
        rate["hz"] = m.dynamic_loop_freq

    sub = rospy.Subscriber(topic + "/State", msgs.RigidBodyState, on_state, queue_size=100, tcp_nodelay=True)
    wsub = rospy.Subscriber("/ambf/env/World/State", msgs.WorldState, on_world, queue_size=10)
    pub = rospy.Publisher(topic + "/Command", msgs.RigidBodyCmd, queue_size=100, tcp_nodelay=True)
    time.sleep(1.5)
    cmd = msgs.RigidBodyCmd(cartesian_cmd_type=msgs.RigidBodyCmd.TYPE_POSITION)
    cmd.pose.orientation.w = 1.0
    n = int(seconds * 1000)
    t_next = time.perf_counter()
    for k in range(1, n + 1):
        cmd.pose.position.x = k * 1e-4  # 0.1 mm apart: AMBF moves a static body only past 1e-5 m
        sent[k] = time.perf_counter()
        pub.publish(cmd)
        t_next += 0.001
        wait = t_next - time.perf_counter()
        if wait > 0:
            time.sleep(wait)
    time.sleep(0.5)
    sub.unregister()
    wsub.unregister()
    pub.unregister()
    ms = np.array(lat) * 1e3
    return {
        "sent": n,
        "seen": len(ms),
        "median_ms": float(np.median(ms)) if len(ms) else float("nan"),
        "p90_ms": float(np.percentile(ms, 90)) if len(ms) else float("nan"),
        "p99_ms": float(np.percentile(ms, 99)) if len(ms) else float("nan"),
        "loop_hz": rate["hz"],
    }


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=3.0)
    args = ap.parse_args()
    from adfkit.ros import msggen
    from adfkit.ros.env import import_ros

    rospy = import_ros()
    msggen.ensure()
    import ambf_msgs.msg as msgs

    port = free_port()
    uri = f"http://127.0.0.1:{port}"
    env = dict(os.environ, ROS_MASTER_URI=uri)
    os.environ["ROS_MASTER_URI"] = uri
    master = subprocess.Popen(
        ["rosmaster", "--core", "-p", str(port)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env
    )
    tmp = Path(tempfile.mkdtemp(prefix="adfkit-rt-"))
    (tmp / "box.yaml").write_text(BOX)
    scenes = [
        ("static box", tmp / "box.yaml", "/ambf/env/marker"),
        ("suturing scene", ROOT / "sample_scenes/suturing/launch.yaml", "/ambf/env/phantom/CameraFrame"),
    ]
    try:
        time.sleep(1.5)
        rospy.init_node("adfkit_roundtrip", anonymous=True, disable_signals=True)
        print(f"{'scene':16} {'seen':>10} {'median':>8} {'p90':>8} {'p99':>8} {'loop Hz':>8}")
        for name, scene, topic in scenes:
            server = subprocess.Popen(
                [sys.executable, "-m", "adfkit", "ros", str(scene), "--no-crtk", "--no-images", "--master", uri],
                stdout=subprocess.PIPE,
                stderr=subprocess.DEVNULL,
                text=True,
                env=env,
            )
            try:
                server.stdout.readline()
                r = measure(rospy, msgs, topic, args.seconds)
            finally:
                server.terminate()
                server.wait(10)
            print(
                f"{name:16} {r['seen']:>5}/{r['sent']:<4} {r['median_ms']:>6.2f}ms {r['p90_ms']:>6.2f}ms "
                f"{r['p99_ms']:>6.2f}ms {r['loop_hz']:>8}"
            )
    finally:
        rospy.signal_shutdown("done")
        master.terminate()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
