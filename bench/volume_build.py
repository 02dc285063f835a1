"""Time and memory to build a volume in each engine and to convert it: for each model file
given (a file with one volume, e.g. the drilling projects' ADF/volume_256.yaml), in a fresh
process each: the PyBullet world (surface pieces within its mesh limits, concave), the MuJoCo
world (the drawn surface and the convex parts), `adfkit convert` to MJCF then MuJoCo loading
it, and to URDF then PyBullet loading it. Prints wall seconds and the process's peak resident
memory. Wall times on a shared machine are noisy; run it twice.

Usage: python bench/volume_build.py MODEL.yaml [MODEL.yaml ...]
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

STEP = r"""
import json, resource, sys, time
sys.path.insert(0, {root!r})
from pathlib import Path
task, path, out = sys.argv[1], sys.argv[2], Path(sys.argv[3])
t0 = time.perf_counter()
extra = {{}}
if task in ("pybullet", "mujoco"):
    from adfkit.adf import load_scene
    from adfkit.runner import open_world
    from adfkit.runner.options import Options
    world = open_world(load_scene(path), Options(), engine=task)
    (rep,) = world.volumes
    extra = {{k: rep[k] for k in ("triangles", "pieces", "convex_parts") if k in rep}}
    world.step(10)
    world.close()
elif task == "mjcf":
    from adfkit.cli import main
    assert main(["convert", path, str(out / "v.xml")]) == 0
    t1 = time.perf_counter()
    import mujoco
    m = mujoco.MjModel.from_xml_path(str(out / "v.xml"))
    extra = {{"convert_s": round(t1 - t0, 2), "load_s": round(time.perf_counter() - t1, 2), "geoms": m.ngeom}}
else:
    from adfkit.cli import main
    assert main(["convert", path, str(out / "v.urdf")]) == 0
    t1 = time.perf_counter()
    import pybullet as pb
    cid = pb.connect(pb.DIRECT)
    pb.loadURDF(str(out / "v.urdf"), useFixedBase=True, physicsClientId=cid)
    extra = {{"convert_s": round(t1 - t0, 2), "load_s": round(time.perf_counter() - t1, 2)}}
print("RESULT " + json.dumps({{"wall_s": round(time.perf_counter() - t0, 2),
      "peak_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss // 1024, **extra}}))
"""


def main() -> int:
    files = sys.argv[1:]
    if not files:
        print(__doc__)
        return 2
    code = STEP.format(root=str(ROOT))
    for f in files:
        print(f"== {f}")
        for task in ("pybullet", "mujoco", "mjcf", "urdf"):
            with tempfile.TemporaryDirectory() as tmp:
                r = subprocess.run(
                    [sys.executable, "-c", code, task, f, tmp], capture_output=True, text=True, check=False
                )
            line = next((x for x in r.stdout.splitlines() if x.startswith("RESULT ")), None)
            if line is None:
                print(f"  {task:9s} failed: {(r.stderr or r.stdout).strip().splitlines()[-1:]}")
                continue
            res = json.loads(line[7:])
            rest = ", ".join(f"{k} {v}" for k, v in res.items() if k not in ("wall_s", "peak_mib"))
            print(f"  {task:9s} {res['wall_s']:7.2f} s  peak {res['peak_mib']:5d} MiB  {rest}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
