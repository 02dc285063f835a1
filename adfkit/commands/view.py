"""`adfkit view SCENE`: play a scene live in a web browser (viser) and print its address.

Listens on localhost only unless --host is given; from another machine, forward the port over
SSH (docs/viewer.md). Runs until Ctrl-C. Exit status 2 for bad input (a missing scene, a port
in use); a scene with errors opens with them listed in the page."""

from __future__ import annotations

import sys
import time

NAME = "view"
HELP = "play a scene live in a web browser (viser): controls, joint sliders, cameras, episode replay"


def add_arguments(p) -> None:
    p.add_argument("scene", help="launch, world or model file, or a folder with a launch.yaml")
    p.add_argument("-l", "--indices", help="launch indices, e.g. 6-11")
    p.add_argument("--engine", choices=("pybullet", "mujoco"), default="pybullet", help="physics engine")
    p.add_argument("--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1: this machine only)")
    p.add_argument("--port", type=int, default=8080, help="port (default 8080)")
    p.add_argument("--episode", help="an `adfkit suture --record` output folder to replay on a timeline")
    p.add_argument("--play", action="store_true", help="start playing at once")


def run(args) -> int:
    from pathlib import Path

    from .. import inputs
    from ..adf import parse_indices
    from ..diagnostics import AdfError, SourceLocation, error
    from ..viewer.server import Viewer

    scene = inputs.scene_file(args.scene)
    inputs.check_file(scene, what="ADF file")
    if not 0 < args.port < 65536:
        raise AdfError(error("bad-option", f"--port {args.port} is not a port number", None, "e.g. --port 8080"))
    episode = Path(args.episode) if args.episode else None
    if episode is not None and not episode.is_dir():
        raise AdfError(
            error(
                "bad-episode",
                f"{inputs.shown(episode)} is not a folder",
                SourceLocation(str(episode)),
                "give the --out folder of `adfkit suture --record`",
            )
        )
    viewer = Viewer(scene, parse_indices(args.indices), args.engine, args.host, args.port, episode)
    viewer.load()
    address = viewer.start()
    print(
        f"adfkit view: {address}  ({'the scene cannot be played: see the findings in the page' if viewer.world is None else scene})"
    )
    if args.host in ("127.0.0.1", "localhost", "::1"):
        print(f"  from another machine: ssh -L {args.port}:localhost:{args.port} THIS-HOST, then open {address}")
    print("  Ctrl-C stops it", flush=True)
    viewer.playing = args.play
    try:
        while True:
            time.sleep(0.5)
            tick = getattr(viewer, "status_tick", None)
            if tick is not None:
                tick()
    except KeyboardInterrupt:
        print("stopped", file=sys.stderr)
    finally:
        viewer.close()
    return 0
