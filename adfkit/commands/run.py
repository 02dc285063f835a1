"""`adfkit run PATH`: play an ADF scene in the PyBullet reference runner (or MuJoCo with
--engine mujoco), headless by default, and write report.json plus each camera's
RGB/depth/segmentation frames."""

from __future__ import annotations

import sys
from pathlib import Path

NAME = "run"
HELP = "play a launch, world or model file in PyBullet or MuJoCo and write a report and camera frames"


def add_arguments(p) -> None:
    p.add_argument("path", help="launch, world or model ADF file")
    p.add_argument("-l", "--indices", help="launch file: multibody configs to load, e.g. 6,7,8,9,10,11 or 6-11")
    p.add_argument("--seconds", type=float, default=5.0, help="simulated time (default 5)")
    p.add_argument(
        "--engine",
        choices=("pybullet", "mujoco"),
        default="pybullet",
        help="physics engine (default pybullet; mujoco: the scene through the MJCF writer, headless)",
    )
    p.add_argument("--gui", action="store_true", help="open the PyBullet window")
    p.add_argument("--out", help="folder for report.json and camera frames")
    p.add_argument("--physics-hz", type=float, default=1000.0, help="physics rate (AMBF: 1000)")
    p.add_argument(
        "--control-substeps",
        type=int,
        default=4,
        help="physics steps per control step (springs, ghosts, gravity overrides); default 4",
    )
    p.add_argument(
        "--solver-iterations",
        type=int,
        default=10,
        help="solver iterations (default 10: Bullet's, as AMBF; PyBullet's own is 50; MuJoCo: Newton iterations)",
    )
    p.add_argument(
        "--contact-threshold",
        type=float,
        help="Bullet contact breaking threshold, m (default Bullet's 0.02; 0.001 plays small scenes faster; PyBullet only)",
    )
    p.add_argument("--gravity", help="override the world gravity, e.g. 0,0,-9.81")
    p.add_argument("--hole-friction", type=float, default=2.0, help="K of F = -K·v inside hole ghosts, N·s/m")
    p.add_argument(
        "--ghosts",
        choices=("ambf", "hole-friction"),
        default="ambf",
        help="what ghosts do: ambf (default; AMBF's ghost objects: a body in one is weightless and loses "
        "10%% of its velocity per contact point and step) or hole-friction (the suture's rule, the "
        "paper's F = -K·v inside hole ghosts only)",
    )
    p.add_argument(
        "--springs",
        choices=("ambf", "implicit"),
        default="ambf",
        help="how the PyBullet runner plays six-dof springs: ambf (default; as AMBF's Bullet, explicit "
        "k·x + c·v at every physics step, k and c capped at m/(16·dt²) and m/dt) or implicit (backward "
        "Euler over the control step, stable at any gain: the suture's)",
    )
    p.add_argument(
        "--bodies",
        choices=("ambf", "pybullet"),
        default="ambf",
        help="what the PyBullet runner's bodies are: ambf (default; AMBF's btRigidBodies: AMBF's estimated inertia, "
        "the box of the collision shape's bounds, where the file gives none, and joints as fast as "
        "AMBF's bodies may turn, π/4 a physics step) or pybullet (PyBullet's estimate and its "
        "multibody's 100 rad/s joint cap: the suture's)",
    )
    p.add_argument("--no-frames", action="store_true", help="do not render camera frames")
    p.add_argument(
        "--renderer",
        choices=("auto", "mujoco", "egl", "tiny"),
        default="tiny",
        help="who draws the PyBullet cameras: tiny (TinyRenderer on the CPU; default, quickest for "
        "the final frames alone), mujoco (the scene mirrored into MuJoCo's OpenGL renderer: ~1 s "
        "to build, then ~15x faster frames), egl (PyBullet's EGL plugin), auto (mujoco, else egl, "
        "else tiny)",
    )
    p.add_argument(
        "--no-ground",
        action="store_true",
        help="a model file played alone gets a floor 1 mm under its lowest body; this leaves it out",
    )


def run(args) -> int:
    from .. import inputs
    from ..adf import load_scene, parse_indices
    from ..diagnostics import AdfError, Severity, error
    from ..report import print_diagnostics
    from ..runner import Options, open_world
    from ..runner.play import play, summary, unstable

    args.path = inputs.scene_file(args.path)  # a folder: its launch.yaml
    inputs.check_file(args.path, what="ADF file")  # a regular file (adfkit.inputs), located errors
    if (
        args.seconds <= 0
        or args.physics_hz <= 0
        or args.control_substeps < 1
        or args.solver_iterations < 1
        or (args.contact_threshold is not None and args.contact_threshold <= 0)
    ):
        raise AdfError(
            error(
                "bad-option",
                "--seconds, --physics-hz and --contact-threshold must be positive, "
                "--control-substeps and --solver-iterations ≥ 1",
                None,
                "e.g. --seconds 5 --physics-hz 1000 --solver-iterations 10",
            )
        )
    if args.gui and args.engine == "mujoco":
        raise AdfError(
            error(
                "bad-option",
                "--gui opens the PyBullet window; the MuJoCo engine plays headless",
                None,
                "drop --gui or use --engine pybullet",
            )
        )
    gravity = None
    if args.gravity:
        try:
            gravity = tuple(float(x) for x in args.gravity.split(","))
            assert len(gravity) == 3
        except (ValueError, AssertionError):
            raise AdfError(
                error("bad-option", f"--gravity {args.gravity!r} is not x,y,z", None, "e.g. --gravity 0,0,-9.81")
            ) from None
    diags: list = []
    scene = load_scene(args.path, parse_indices(args.indices), diags)
    # the validator's severities: what AMBF loads anyway (duplicate keys, sb/cloth.yaml) is a warning
    from dataclasses import replace

    from ..validator.engine import SEVERITY_OVERRIDES

    diags = [replace(d, severity=SEVERITY_OVERRIDES.get(d.rule, d.severity)) for d in diags]
    print_diagnostics(diags, sys.stderr)
    if any(d.severity >= Severity.ERROR for d in diags):
        return 2
    opt = Options(
        physics_hz=args.physics_hz,
        control_substeps=args.control_substeps,
        solver_iterations=args.solver_iterations,
        contact_threshold=args.contact_threshold,
        gravity=gravity,
        hole_friction=args.hole_friction,
        ghosts=args.ghosts,
        springs=args.springs,
        link_shapes="body",
        bodies=args.bodies,
        ground=not args.no_ground,
        renderer="tiny" if args.no_frames else args.renderer,
    )
    world = open_world(scene, opt, gui=args.gui and args.engine == "pybullet", engine=args.engine)
    try:
        print_diagnostics(world.diagnostics, sys.stderr)
        report = play(world, args.seconds, Path(args.out) if args.out else None, not args.no_frames, str(args.path))
    finally:
        world.close()
    print(summary(report))
    if args.out:
        print(f"report: {(Path(args.out) / 'report.json').resolve()}")
    if unstable(report):
        print(
            f"unstable: nan {report['nan']}, exploded {report['exploded']}, fell {report['fell_through_floor']}",
            file=sys.stderr,
        )
        for e in report.get("instabilities", []):
            print(f"  t = {e['time_s']:.3f} s, {e['body'] or 'the scene'}: {e['message']}", file=sys.stderr)
        return 1
    return 0
