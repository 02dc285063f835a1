"""The planner's tool clearance (adfkit/tasks/clearance.py): the tissue's shapes measured against
PyBullet's own distance query, the tool's shapes placed for any end-effector pose as the
simulated PSM places them, and the grasps the planner chooses keeping off the tissue."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pb = pytest.importorskip("pybullet")

ROOT = Path(__file__).resolve().parents[1]
BUNDLED = ROOT / "sample_scenes" / "suturing" / "launch.yaml"


@pytest.fixture(scope="module")
def world():
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    if not BUNDLED.is_file():
        pytest.skip("sample_scenes/suturing is not in this checkout")
    w = open_world(load_scene(BUNDLED), Options(renderer="tiny"))
    yield w
    w.close()


def _tissue_bodies(world):
    needle = world.body("Needle")
    return [sb for sb in world.bodies if sb.model is needle.model and sb.static]


def test_tissue_distance_agrees_with_pybullet(world):
    """Points around hole pair 1: the distance from the scene's own shapes is within 0.1 mm of
    Bullet's closest points (its boxes' edges are rounded by their 0.1 mm margins), and never
    more than it by over 0.05 mm (the check errs toward the tissue). The hole boundaries'
    capsules were taken 0.6 mm longer at each end (their height includes the caps): 0.47 mm."""
    from adfkit.tasks.clearance import Tissue
    from adfkit.tasks.holes import hole_frame
    from adfkit.tasks.suture import hole_pairs

    static = _tissue_bodies(world)
    tissue = Tissue(static)
    assert len(tissue.boxes) == 10 and len(tissue.segments) == 32  # the phantom's boxes, 8 holes x 4 capsules
    cid = world.cid
    sphere = pb.createCollisionShape(pb.GEOM_SPHERE, radius=1e-5, physicsClientId=cid)
    probe = pb.createMultiBody(0, sphere, basePosition=[0, 0, 1], physicsClientId=cid)
    centre = hole_frame(world, hole_pairs(world)[0].entry)[:3, 3]
    rng = np.random.default_rng(0)
    diffs = []
    try:
        for _ in range(120):
            p = centre + rng.uniform(-0.015, 0.015, 3)
            pb.resetBasePositionAndOrientation(probe, p.tolist(), [0, 0, 0, 1], physicsClientId=cid)
            bullet = min(
                (
                    c[8]
                    for sb in static
                    for c in pb.getClosestPoints(probe, sb.uid, 0.05, -1, sb.link, physicsClientId=cid)
                ),
                default=None,
            )
            if bullet is not None:
                diffs.append(tissue.distance(p[None]) - bullet)
    finally:
        pb.removeBody(probe, physicsClientId=cid)
    diffs = np.array(diffs)
    assert len(diffs) > 100
    assert diffs.max() < 5e-5 and diffs.min() > -1e-4


def test_tool_capsule_points_stand_for_its_surface(tmp_path):
    """A tool link's capsule (the corpus PSM's wrist pitch link: 13 mm long with its caps, 3.5 mm
    radius, turned) is points along its axis with its radius: the distance they give from points
    around it is Bullet's within 0.05 mm. The corners of the box around it stood up to 2.6 mm off
    it, and the planner took every grasp of the corpus needle as 5 mm into the tissue."""
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world
    from adfkit.tasks.clearance import _primitive_points

    (tmp_path / "model.yaml").write_text(
        """bodies: [BODY link]
BODY link:
  name: link
  mass: 0.0
  collision shape: CAPSULE
  collision geometry: {axis: X, height: 0.013, radius: 0.0035}
  collision offset: {position: {x: 0.0041, y: 0.0, z: 0.0001}, orientation: {r: 0.3, p: 0.0, y: 0.2}}
  location: {position: {x: 0.1, y: -0.05, z: 0.2}, orientation: {r: 0.4, p: -0.7, y: 1.1}}
"""
    )
    w = open_world(load_scene(tmp_path / "model.yaml", None, []), Options(ground=False, visuals=False))
    try:
        link = w.body("BODY link")
        pts, radii = _primitive_points(link)
        centre = pts.mean(axis=0)
        sphere = pb.createCollisionShape(pb.GEOM_SPHERE, radius=1e-5, physicsClientId=w.cid)
        probe = pb.createMultiBody(0, sphere, basePosition=[0, 0, 1], physicsClientId=w.cid)
        rng = np.random.default_rng(1)
        diffs = []
        for _ in range(200):
            p = centre + rng.uniform(-0.012, 0.012, 3)
            pb.resetBasePositionAndOrientation(probe, p.tolist(), [0, 0, 0, 1], physicsClientId=w.cid)
            cps = pb.getClosestPoints(probe, link.uid, 0.05, -1, link.link, physicsClientId=w.cid)
            ours = float((np.linalg.norm(pts - p, axis=1) - radii).min())
            if cps and ours > 0:
                diffs.append(ours - min(c[8] for c in cps))
        diffs = np.array(diffs)
        assert len(diffs) > 100
        assert np.abs(diffs).max() < 5e-5
    finally:
        w.close()


def test_tool_shape_follows_the_simulated_tool_at_any_configuration(world):
    """ToolShape places the jaws, the wrist's pitch link and the shaft from the end effector's
    pose alone: at random joint values they coincide with the simulated bodies' shapes, whether
    it was sampled with the tool inserted or drawn into its cannula."""
    from adfkit.runner.psm import PSM
    from adfkit.tasks.clearance import ToolShape, _primitive_points

    psm = PSM(world, "psm1")
    saved = world.joint_state(psm.art, psm.arm)
    inserted = ToolShape(world, psm)
    recs = psm.art.records
    rng = np.random.default_rng(3)
    lo, hi = psm.kin.lower_limits[:6], psm.kin.upper_limits[:6]
    try:
        # sampled with the tool drawn into its cannula too (the corpus PSMs start at insertion
        # 0, under L_tool2rcm, where the palm points away from the remote centre): its wrist's
        # points were then mirrored, 11-15 mm off, at every other pose
        world.reset_joints(psm.art, psm.arm, np.zeros(6))
        drawn_in = ToolShape(world, psm)
        world.reset_joints(psm.art, psm.arm, *saved)
        for tool in (inserted, drawn_in) * 3:
            world.reset_joints(psm.art, psm.arm, lo + (hi - lo) * (0.2 + 0.6 * rng.random(6)))
            ee = psm.base_in_world() @ psm.measured_cp()
            pts, radii = tool.points(ee[None])
            jaws = np.concatenate(
                [_primitive_points(recs[psm.arm[5]][3])[0]] + [_primitive_points(recs[j][3])[0] for j in psm.jaws]
            )
            palm = _primitive_points(recs[psm.arm[4]][3])[0]
            n, m = len(tool.ee_pts), len(tool.palm_pts)
            assert np.abs(pts[0, :n] - jaws).max() < 1e-9
            assert np.abs(pts[0, n : n + m] - palm).max() < 1e-9
            shaft = recs[psm.arm[3]][3].world_matrix()
            rel = pts[0, n + m :] - shaft[:3, 3]
            axis = shaft[:3, 2]
            assert np.linalg.norm(rel - np.outer(rel @ axis, axis), axis=1).max() < 1e-9  # on the shaft's axis
            assert radii[n + m :] == pytest.approx(0.0042)  # the roll link's cylinder
    finally:
        world.reset_joints(psm.art, psm.arm, *saved)


def test_the_planned_grasps_keep_the_tools_off_the_tissue(world):
    """On the bundled scene the planner finds, for every pair after the first, driving grasps
    whose tool stays at least 0.9 mm off the tissue along the whole insertion; every pull keeps
    the puller SURE_CLEARANCE off it. Pairs 2-4 pull the tail 25 degrees beyond the exit; at
    pair 1 the wrist, turning with the needle, would bring the jaws within 0.4 mm of the tissue
    there, so that pull ends sooner."""
    import math

    from adfkit.tasks.suture import JAW_APPROACH, SURE_CLEARANCE, SutureTask

    task = SutureTask(world, [1, 2, 3, 4], seed=0)
    for psm in task.psms.values():
        psm.servo_jaw(JAW_APPROACH)  # as the task opens them before it plans
    world.step(300)
    task.plan()
    assert [round(g.clearance, 4) >= 0.0 for g in task.drive_grasps] == [True] * 4
    assert min(g.clearance for g in task.drive_grasps[1:]) >= 0.0009
    assert min(g.clearance for g in task.pull_grasps) >= SURE_CLEARANCE
    assert [round(math.degrees(a)) for a in task.tail_clears[1:]] == [25, 25, 25]
    assert math.degrees(task.tail_clears[0]) < 25
