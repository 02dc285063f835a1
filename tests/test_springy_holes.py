"""bench/springy_holes.py: the bundled suturing scene with the challenge phantom's springy holes
(docs/parity.md, "The bundled scene at rest") is written as it says, and its hole bodies slide
along the phantom's x on their springs and not across."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np

BENCH = Path(__file__).resolve().parent.parent / "bench" / "springy_holes.py"


def test_the_copy_hangs_every_hole_on_a_spring_that_slides_it_toward_the_exit(tmp_path):
    from adfkit.adf import load, load_scene
    from adfkit.runner import Options, open_world

    out = tmp_path / "springy"
    subprocess.run([sys.executable, str(BENCH), str(out)], check=True, capture_output=True)
    m = load(out / "phantom" / "phantom.yaml")
    springs = {j.child: j for j in m.joints if (j.parent or "").endswith("Phantom")}
    holes = [b for b in m.bodies if (b.name or "").startswith(("Entry", "Exit"))]
    assert sorted(springs) == sorted(b.identifier for b in holes) and len(holes) == 8
    assert all(b.mass == 0.2 for b in holes)
    threads = [b for b in m.bodies if (b.name or "").startswith("Thread")]
    assert len(threads) == 40 and all(b.inertia.ix == 5e-5 for b in threads)
    joints = [j for j in m.joints if j.type == "six dof spring" and "Thread" in (j.child or "")]
    assert len(joints) == 39 and all((j.stiffness.angular.x, j.damping.angular.x) == (0.2, 0.01) for j in joints)

    world = open_world(load_scene(out / "launch.yaml"), Options(visuals=False))
    try:
        exit1 = world.body("BODY Exit1")
        at = exit1.world_matrix()[:3, 3]
        steps = int(round(0.5 / (world.dt * world.opt.control_substeps)))
        moved = []
        for push in ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]):  # 1 N along the slide (100 N/m), then across it
            for _ in range(steps):
                exit1.force(push, exit1.com_position())
                world.step(1)
            moved.append(exit1.world_matrix()[:3, 3] - at)
        assert 0.009 < moved[0][0] < 0.0115  # to the slide's 10 mm limit
        assert abs(moved[1][1]) < 0.001  # across it the limits hold it
        # the bundled scene as built: the same push does not move its static holes
        world.close()
        world = open_world(
            load_scene(Path(BENCH).parent.parent / "sample_scenes" / "suturing" / "launch.yaml"), Options(visuals=False)
        )
        exit1 = world.body("BODY Exit1")
        at = exit1.world_matrix()[:3, 3]
        for _ in range(steps):
            exit1.force([1.0, 0.0, 0.0], exit1.com_position())
            world.step(1)
        assert np.linalg.norm(exit1.world_matrix()[:3, 3] - at) < 1e-9
    finally:
        world.close()
