"""`adfkit ros SCENE`: play a scene and serve it over ROS 1 as AMBF 2.0 does (ambf_msgs
topics under /ambf/env/, what AMBF's ambf_client connects to), plus the challenge's CRTK topics
and, with --teleop, an input device driving a PSM. Runs until Ctrl-C. Needs Debian's ROS 1
packages (make ros); exit status 2 when they, the scene or the ROS master are missing."""

from __future__ import annotations

import sys

NAME = "ros"
HELP = "serve a played scene over ROS as AMBF does (ambf_client, CRTK topics, teleoperation)"


def add_arguments(p) -> None:
    p.add_argument("scene", help="launch, world or model file, or a folder with a launch.yaml")
    p.add_argument("-l", "--indices", help="launch indices, e.g. 6-11")
    p.add_argument("--engine", choices=("pybullet", "mujoco"), default="pybullet", help="physics engine")
    p.add_argument(
        "--rate",
        type=float,
        default=1000.0,
        help="loop steps a second, paced to real time: commands applied and states published each step (AMBF's -p; default 1000; below 1000 each step is several 1 ms physics steps)",
    )
    p.add_argument("--master", help="ROS master URI (default: $ROS_MASTER_URI, else http://localhost:11311)")
    p.add_argument("--no-crtk", action="store_true", help="do not serve the CRTK topics (/CRTK/psm1/...)")
    p.add_argument("--no-images", action="store_true", help="do not publish camera images or depth")
    p.add_argument(
        "--teleop",
        action="append",
        default=[],
        metavar="DEVICE=PSM",
        help="drive a PSM from an input device: geomagic=psm1 (/Geomagic/pose, /Geomagic/button), "
        "joy=psm2 (/joy, sensor_msgs/Joy); a topic prefix may follow: geomagic:/MyDevice=psm1",
    )
    p.add_argument(
        "--solver-iterations",
        type=int,
        default=10,
        help="the physics solver's iterations a step (default 10, AMBF's; the scripted suture plays with 50)",
    )
    p.add_argument(
        "--watchdog",
        type=float,
        default=0.5,
        metavar="S",
        help="seconds without a command after which an object's command is reset and a world's "
        "step throttling ends (default 0.5, AMBF's); longer for clients on a busy machine",
    )
    p.add_argument("--seconds", type=float, help="stop after this many seconds of wall time")


def run(args) -> int:
    from .. import inputs
    from ..adf import parse_indices
    from ..diagnostics import AdfError, error
    from ..ros.server import RosServer

    scene = inputs.scene_file(args.scene)
    inputs.check_file(scene, what="ADF file")
    if args.solver_iterations < 1:
        raise AdfError(
            error("bad-option", "--solver-iterations must be at least 1", None, "e.g. --solver-iterations 10")
        )
    if not 0.0 < args.watchdog < float("inf"):
        raise AdfError(
            error("bad-option", f"--watchdog {args.watchdog:g} is not a time out", None, "e.g. --watchdog 0.5")
        )
    if not 1.0 <= args.rate <= 100000.0:
        raise AdfError(error("bad-option", f"--rate {args.rate:g} is not a physics rate", None, "e.g. --rate 1000"))
    from ..ros.teleop import parse

    for spec in args.teleop:
        parse(spec)
    server = RosServer(
        scene,
        parse_indices(args.indices),
        args.engine,
        args.rate,
        args.master,
        crtk=not args.no_crtk,
        teleop=args.teleop,
        images=not args.no_images,
        solver_iterations=args.solver_iterations,
        watchdog_s=args.watchdog,
        log=lambda text: print(text, file=sys.stderr, flush=True),
    )
    try:
        server.start()
        print(f"adfkit ros: {scene} on {server.master}: {server.summary()}", flush=True)
        print("  Ctrl-C stops it", flush=True)
        server.run(args.seconds)
    except KeyboardInterrupt:
        print("stopped", file=sys.stderr)
    finally:
        server.close()
    return 0
