"""Conversion times, and URDF → MJCF against MuJoCo's own URDF compiler and urdf2mjcf.
Prints figures; asserts nothing.

    .venv/bin/python bench/convert.py [--repeat 5]

Per model: ADF → URDF, ADF → MJCF (corpus robots), URDF → ADF and MJCF → ADF (pybullet_data
URDFs, dm_control models). For URDF → MJCF on the same files in the same run:
- adfkit: read URDF into the scene model, write MJCF;
- MuJoCo: `MjModel.from_xml_path(urdf)` + `mj_saveLastXML` (its built-in URDF compiler, which
  also compiles the model, so it does more work than a file conversion);
- urdf2mjcf (`pip install urdf2mjcf`; skipped with a note when not installed).
Each time is the best of --repeat runs in this process.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CORPUS = Path(os.environ.get("ADFKIT_CORPUS", ROOT.parent / "shared" / "corpus"))
ROBOTS = CORPUS / "ambf" / "ambf_models" / "descriptions" / "multi-bodies" / "robots"


def best(fn, repeat: int) -> float:
    out = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        out = min(out, time.perf_counter() - t0)
    return out


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    import mujoco
    import pybullet_data

    from adfkit.adf.reader import load
    from adfkit.converters import mjcf, urdf

    tmp = Path(tempfile.mkdtemp(prefix="adfkit-bench-"))
    print(f"{'model':34s} {'conversion':14s} {'ms':>8s}")
    if ROBOTS.is_dir():
        for name in ("blender-kuka", "blender-psm", "blender-ecm", "blender-mtm"):
            model = load(ROBOTS / f"{name}.yaml")
            for fmt, mod, ext in (("ADF → URDF", urdf, ".urdf"), ("ADF → MJCF", mjcf, ".xml")):
                t = best(lambda: mod.write(model, tmp / f"{name}{ext}"), args.repeat)
                print(f"{name:34s} {fmt:14s} {t * 1e3:8.2f}")
    else:
        print(f"(corpus not found at {CORPUS}: ADF rows skipped)")
    data = Path(pybullet_data.getDataPath())
    urdfs = ["kuka_iiwa/model.urdf", "r2d2.urdf", "franka_panda/panda.urdf", "racecar/racecar.urdf", "cartpole.urdf"]
    for rel in urdfs:
        t = best(lambda: urdf.read(data / rel), args.repeat)
        print(f"{rel:34s} {'URDF → ADF':14s} {t * 1e3:8.2f}")
    try:
        import dm_control

        suite = Path(dm_control.__file__).parent / "suite"
        for name in ("cartpole.xml", "acrobot.xml", "cheetah.xml", "humanoid.xml"):
            t = best(lambda: mjcf.read(suite / name), args.repeat)
            print(f"{'dm_control/' + name:34s} {'MJCF → ADF':14s} {t * 1e3:8.2f}")
    except ImportError:
        print("(dm_control not installed: MJCF → ADF rows skipped)")

    try:
        import logging

        from urdf2mjcf.convert import convert_urdf_to_mjcf

        logging.disable(logging.WARNING)  # urdf2mjcf logs every fallback it takes
    except ImportError:
        convert_urdf_to_mjcf = None
    print()
    print(f"URDF → MJCF, best of {args.repeat} (ms); ratio = other / adfkit")
    print(f"{'model':34s} {'adfkit':>8s} {'MuJoCo':>8s} {'ratio':>6s} {'urdf2mjcf':>10s} {'ratio':>6s}")
    for rel in urdfs:
        src = data / rel
        out = tmp / (Path(rel).stem + "_adfkit.xml")

        def ours():
            mjcf.write(urdf.read(src)[0], out)

        def theirs():
            mujoco.mj_saveLastXML(str(tmp / (Path(rel).stem + "_mujoco.xml")), mujoco.MjModel.from_xml_path(str(src)))

        try:
            t_ours = best(ours, args.repeat)
            mujoco.MjModel.from_xml_path(str(out))  # what we wrote compiles
        except Exception as exc:  # noqa: BLE001 - a bench reports and goes on
            print(f"{rel:34s} adfkit failed: {exc}")
            continue
        try:
            t_mj = best(theirs, args.repeat)
            mj = f"{t_mj * 1e3:8.2f} {t_mj / t_ours:6.2f}"
        except Exception as exc:  # noqa: BLE001
            mj = f"{'failed':>8s} {'':6s}  ({str(exc).splitlines()[0][:40]})"
        if convert_urdf_to_mjcf is not None:
            try:
                t_u2m = best(lambda: convert_urdf_to_mjcf(src, tmp / (Path(rel).stem + "_u2m.xml")), args.repeat)
                u2m = f"{t_u2m * 1e3:10.2f} {t_u2m / t_ours:6.2f}"
            except Exception as exc:  # noqa: BLE001
                u2m = f"{'failed':>10s}  ({type(exc).__name__})"
        else:
            u2m = f"{'n/a':>10s}  (pip install urdf2mjcf)"
        print(f"{rel:34s} {t_ours * 1e3:8.2f} {mj} {u2m}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
