"""How close a PSM's tool would come to the tissue at a planned end-effector pose.

The planner asks this before it commits to a grasp, so that the jaws and the wrist stay off the
phantom while the tools collide with it (nothing is switched off to make the plan work). It is
answered from the scene's own collision shapes, not from the engine: primitives of the tissue
bodies (boxes, capsules, spheres, cylinders, planes), the triangles of a static body's concave
collision mesh (AMBF's default mesh type, as AMBF and PyBullet collide it: ``mesh_distance``) and
the convex pieces of the other collision meshes (one hull per sub-mesh of an OBJ file, as the
engines build them; MuJoCo collides every mesh so), against points sampled on the tool's
collision primitives near its end effector.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..adf.paths import collision_mesh_path
from ..model.semantics import ShapeKind, axis_vector, collision_primitives, concave_mesh
from ..runner.rotations import invert, pose_to_matrix
from .mesh_distance import TriangleMeshes, obj_triangles

FIELD_HALF = 0.045  # m: a distance field reaches this far each way from its centre ...
FIELD_STEP = 0.0015  # m ... on a grid this fine (exact at its nodes, trilinear between them)
FIELD_BLOCK = 8  # nodes a side of the blocks a field is computed in
# m: a field's node is exact up to this distance from the tissue, and at least this far beyond.
# Enough: a query (capped at TOOL_CLEARANCE, 1.5 mm) interpolates the 8 nodes of its cell, all
# within a cell's diagonal (2.6 mm) of each other, as a distance is 1-Lipschitz; so a query
# under 1.5 mm reads only nodes nearer than 4.1 mm, and one that reads a node of 10 mm or more
# is at least 7.4 mm off the tissue and capped either way
FIELD_EXACT = 0.010
SAMPLE_EDGE = 0.004  # m: a tool shape longer than this along an axis is also sampled at its middle
AXIS_STEP = 0.001  # m between the points along a capsule's axis (its surface within 0.04 mm at 3.5 mm radius)


def _num(v, default: float = 0.0) -> float:
    return float(v) if isinstance(v, (int, float)) else default


def _obj_groups(path: Path) -> list[np.ndarray]:
    """Vertices of each convex piece of an OBJ collision mesh as the engines build them (each
    object's faces of each material, ``adfkit.geometry.objpieces``)."""
    from ..geometry.objpieces import obj_pieces

    with open(path, encoding="utf-8", errors="replace") as f:
        try:
            pieces = obj_pieces(f.read())
        except ValueError:  # a face that names no vertex: the engines do not make the body
            return []
    return [np.array(v, dtype=float) for v, _ in pieces if len(v) >= 4]


def _hull_planes(v: np.ndarray):
    """(normals, offsets) of the convex hull of v: n·x + d <= 0 inside; None when flat."""
    from scipy.spatial import ConvexHull, QhullError

    try:
        h = ConvexHull(v)
    except (QhullError, ValueError):
        return None
    return h.equations[:, :3], h.equations[:, 3]


class _Field:
    """The tissue's signed distance on the nodes of a cube of FIELD_STEP around ``centre``,
    computed a block of FIELD_BLOCK³ nodes at a time from the shapes near it, the first time a
    query falls in it: the planner's queries stay near the tools' paths, so most of the cube is
    never computed."""

    def __init__(self, tissue: Tissue, centre: np.ndarray) -> None:
        self.tissue, self.centre = tissue, centre
        self.origin = centre - FIELD_HALF
        self.n = n = int(round(2 * FIELD_HALF / FIELD_STEP)) + 1
        self.axes = [self.origin[i] + FIELD_STEP * np.arange(n) for i in range(3)]
        self.grid = np.zeros((n, n, n))
        self.done = np.zeros((-(-n // FIELD_BLOCK),) * 3, dtype=bool)

    def ensure(self, idx: np.ndarray) -> None:
        """Compute every block holding a node that trilinear lookups at ``idx`` (3, M: fractional
        node coordinates) read: the node below and the one above each, clamped to the cube."""
        lo = np.clip(np.floor(idx).astype(int), 0, self.n - 1)
        hi = np.minimum(lo + 1, self.n - 1)
        b, nb = FIELD_BLOCK, self.done.shape[0]
        wanted = np.zeros(self.done.size, dtype=bool)
        for c in range(8):  # the 8 corners of each lookup's cell, as block numbers
            i, j, k = ((hi if (c >> a) & 1 else lo)[a] // b for a in range(3))
            wanted[(i * nb + j) * nb + k] = True
        todo = np.flatnonzero(wanted & ~self.done.ravel())
        for i, j, k in zip(*np.unravel_index(todo, self.done.shape)):
            sl = tuple(slice(v * b, min((v + 1) * b, self.n)) for v in (i, j, k))
            nodes = np.stack(np.meshgrid(*(ax[s] for ax, s in zip(self.axes, sl)), indexing="ij"), axis=-1)
            pts = nodes.reshape(-1, 3)
            mid = (pts[0] + pts[-1]) / 2
            half = float(np.linalg.norm(pts[-1] - pts[0])) / 2
            # the shapes within FIELD_EXACT of the block: a node farther than that from the
            # tissue gets a value as far or farther, which no clearance query can tell apart
            self.grid[sl] = self.tissue.exact(pts, mid, half + FIELD_EXACT).reshape(nodes.shape[:3])
            self.done[i, j, k] = True


class Tissue:
    """The collision shapes of the static tissue bodies, in the world, for distance queries."""

    def __init__(self, bodies, centres=(), triangles: bool = True) -> None:
        """``centres``: where the queries will be (a distance field is made around each, the
        first time a query is nearest to it); without any, around each query's own centimetre.
        ``triangles``: a static body's concave collision mesh read as its triangles, as AMBF and
        PyBullet collide it (False: as the hulls of its pieces, as MuJoCo collides it)."""
        self.triangles = triangles
        self.boxes: list[tuple[np.ndarray, np.ndarray]] = []  # (world-from-box 4x4, half extents)
        self.segments: list[tuple[np.ndarray, np.ndarray, float]] = []  # capsules, spheres, cones
        self.cylinders: list[tuple[np.ndarray, np.ndarray, float, float]] = []  # (centre, axis, half height, radius)
        self.planes: list[tuple[np.ndarray, float]] = []  # (normal, offset): n·x <= offset is inside
        self.hulls: list[tuple[np.ndarray, np.ndarray]] = []
        self.meshes: list[TriangleMeshes] = []  # static concave collision meshes, as their triangles
        self.unknown: list[str] = []  # bodies whose shapes could not be read (left out, named)
        for sb in bodies:
            self._add(sb)
        self._stack()
        self._fields: dict[tuple, _Field] = {}
        self.centres = np.array([tuple(np.round(c, 3)) for c in centres]).reshape(-1, 3)

    def _add(self, sb) -> None:
        t = sb.world_matrix()
        body = sb.body
        prims = collision_primitives(body)
        if prims is None:
            path = collision_mesh_path(sb.model, body)
            if path is None or path.suffix.lower() != ".obj" or not path.is_file():
                self.unknown.append(sb.name)
                return
            s = _num(body.scale, 1.0)
            if self.triangles and sb.static and concave_mesh(body):
                mesh = obj_triangles(path, s, t)
                if mesh is None:
                    self.unknown.append(sb.name)
                else:
                    self.meshes.append(mesh)
                return
            for v in _obj_groups(path):
                v = (t[:3, :3] @ (v * s).T).T + t[:3, 3]
                planes = _hull_planes(v)
                if planes is not None:
                    self.hulls.append(planes)
            return
        for p in prims:
            m = t @ pose_to_matrix(p.pose)
            g = p.geometry
            c = m[:3, 3]
            if p.kind is ShapeKind.BOX:
                self.boxes.append((m, np.array([_num(g.x), _num(g.y), _num(g.z)]) / 2))
            elif p.kind is ShapeKind.SPHERE:
                self.segments.append((c, c, _num(g.radius)))
            elif p.kind in (ShapeKind.CAPSULE, ShapeKind.CYLINDER, ShapeKind.CONE):
                a = axis_vector(g.axis)
                u = m[:3, :3] @ np.array([a.x, a.y, a.z], dtype=float)
                h = _num(g.height) / 2
                if p.kind is ShapeKind.CYLINDER:  # exact: as a capsule its caps filled the channels
                    # beside a curved ridge of 12 mm radius (a phantom's), 12 mm past each end
                    self.cylinders.append((c, u, h, _num(g.radius)))
                    continue
                if p.kind is ShapeKind.CAPSULE:  # its height includes the caps (adf-format.md §7.5)
                    h = max(h - _num(g.radius), 0.0)
                # a cone lies inside the capsule of its base radius along its axis
                self.segments.append((c - h * u, c + h * u, _num(g.radius)))
            elif p.kind is ShapeKind.PLANE and g.normal is not None:
                n = m[:3, :3] @ np.array([_num(g.normal.x), _num(g.normal.y), _num(g.normal.z)], dtype=float)
                n /= max(float(np.linalg.norm(n)), 1e-12)
                self.planes.append((n, float(n @ c) + _num(g.offset)))

    def _stack(self) -> None:
        """The shapes as arrays, so that one query is a few numpy operations, each with a
        bounding sphere, so that a query looks only at the shapes near it."""
        self._box_r = np.array([m[:3, :3] for m, _ in self.boxes]).reshape(-1, 3, 3)
        self._box_c = np.array([m[:3, 3] for m, _ in self.boxes]).reshape(-1, 3)
        self._box_h = np.array([h for _, h in self.boxes]).reshape(-1, 3)
        self._seg_a = np.array([a for a, _, _ in self.segments]).reshape(-1, 3)
        self._seg_ab = np.array([b - a for a, b, _ in self.segments]).reshape(-1, 3)
        self._seg_r = np.array([r for _, _, r in self.segments])
        self._cyl_c = np.array([c for c, _, _, _ in self.cylinders]).reshape(-1, 3)
        self._cyl_u = np.array([u for _, u, _, _ in self.cylinders]).reshape(-1, 3)
        self._cyl_h = np.array([h for _, _, h, _ in self.cylinders])
        self._cyl_r = np.array([r for _, _, _, r in self.cylinders])
        self._cyl_reach = np.hypot(self._cyl_h, self._cyl_r)
        self._plane_n = np.array([n for n, _ in self.planes]).reshape(-1, 3)
        self._plane_d = np.array([d for _, d in self.planes])
        self._box_reach = np.linalg.norm(self._box_h, axis=1)
        self._seg_mid = self._seg_a + self._seg_ab / 2
        self._seg_reach = np.linalg.norm(self._seg_ab, axis=1) / 2 + self._seg_r

    def exact(self, pts: np.ndarray, near: np.ndarray, radius: float) -> np.ndarray:
        """The signed distance, m, from each point (M, 3) to the tissue (negative: inside),
        looking at the shapes within ``radius`` of ``near``; at most ``radius`` where none is."""
        best = np.full(len(pts), radius)
        boxes = np.flatnonzero(np.linalg.norm(self._box_c - near, axis=1) < radius + self._box_reach)
        if len(boxes):
            local = np.einsum("bnj,bjk->bnk", pts[None, :, :] - self._box_c[boxes, None, :], self._box_r[boxes])
            q = np.abs(local) - self._box_h[boxes, None, :]
            d = np.sqrt((np.maximum(q, 0.0) ** 2).sum(axis=2)) + np.minimum(q.max(axis=2), 0.0)
            best = np.minimum(best, d.min(axis=0))
        segs = np.flatnonzero(np.linalg.norm(self._seg_mid - near, axis=1) < radius + self._seg_reach)
        if len(segs):
            ap = pts[None, :, :] - self._seg_a[segs, None, :]
            ab = self._seg_ab[segs, None, :]
            t = np.clip((ap * ab).sum(axis=2) / np.maximum((ab * ab).sum(axis=2), 1e-18), 0.0, 1.0)
            d = np.sqrt(((ap - t[:, :, None] * ab) ** 2).sum(axis=2)) - self._seg_r[segs, None]
            best = np.minimum(best, d.min(axis=0))
        cyls = np.flatnonzero(np.linalg.norm(self._cyl_c - near, axis=1) < radius + self._cyl_reach)
        if len(cyls):
            cp = pts[None, :, :] - self._cyl_c[cyls, None, :]
            along = (cp * self._cyl_u[cyls, None, :]).sum(axis=2)
            across = np.linalg.norm(cp - along[:, :, None] * self._cyl_u[cyls, None, :], axis=2)
            q_r = across - self._cyl_r[cyls, None]
            q_h = np.abs(along) - self._cyl_h[cyls, None]
            d = np.minimum(np.maximum(q_r, q_h), 0.0) + np.hypot(np.maximum(q_r, 0.0), np.maximum(q_h, 0.0))
            best = np.minimum(best, d.min(axis=0))
        if len(self._plane_d):
            best = np.minimum(best, (pts @ self._plane_n.T - self._plane_d).min(axis=1))
        for normals, offsets in self.hulls:
            best = np.minimum(best, (pts @ normals.T + offsets).max(axis=1))
        for mesh in self.meshes:
            best = np.minimum(best, mesh.exact(pts, near, radius))
        return best

    def field(self, near: np.ndarray) -> _Field:
        """The signed distance field on a grid of FIELD_STEP around the centre nearest to
        ``near`` (made once and kept; its nodes computed a block at a time as queries need them)."""
        if len(self.centres):
            key = tuple(self.centres[int(np.argmin(np.linalg.norm(self.centres - near, axis=1)))])
        else:
            key = tuple(np.round(near, 2))
        if key not in self._fields:
            self._fields[key] = _Field(self, np.array(key))
        return self._fields[key]

    def distances(self, pts: np.ndarray, radii: np.ndarray, near: np.ndarray) -> np.ndarray:
        """For each set of points (C, N, 3) near ``near``: the least signed distance, m, from its
        points (less their radii, (N,)) to the tissue, from the field around ``near``
        (trilinear between its nodes)."""
        from scipy.ndimage import map_coordinates

        f = self.field(near)
        idx = ((pts.reshape(-1, 3) - f.origin) / FIELD_STEP).T
        f.ensure(idx)
        d = map_coordinates(f.grid, idx, order=1, mode="nearest").reshape(pts.shape[0], -1)
        return (d - radii).min(axis=1)

    def distance(self, pts: np.ndarray) -> float:
        """The least signed distance, m, from the points (N, 3) to the tissue (exact)."""
        centre = pts.mean(axis=0)
        reach = float(np.linalg.norm(pts - centre, axis=1).max()) + 1.0
        return float(self.exact(pts, centre, reach).min())


def _primitive_points(sb) -> tuple[np.ndarray, np.ndarray]:
    """Points that stand for a body's collision primitives, in the world, each with a radius (a
    point's clearance is the tissue's distance less its radius): a sphere's centre and points
    along a capsule's axis, AXIS_STEP apart, with their radius (their surface: the corners of the
    box around the corpus PSM's capsule wrist link stood up to 2.6 mm off it); the corners (and
    the middles of long edges) of a box's, a cylinder's or a cone's bounding box."""
    t = sb.world_matrix()
    out, radii = [], []
    for p in collision_primitives(sb.body) or []:
        g = p.geometry
        m = t @ pose_to_matrix(p.pose)
        if p.kind in (ShapeKind.SPHERE, ShapeKind.CAPSULE):
            r = _num(g.radius)
            u = np.zeros(3)
            if p.kind is ShapeKind.CAPSULE:  # its height includes the caps (adf-format.md §7.5)
                a = axis_vector(g.axis)
                u = np.array([a.x, a.y, a.z], dtype=float) * max(_num(g.height) / 2 - r, 0.0)
            n = int(math.ceil(2 * float(np.linalg.norm(u)) / AXIS_STEP)) + 1
            local = np.linspace(-1.0, 1.0, n)[:, None] * u if n > 1 else np.zeros((1, 3))
            out.append((m[:3, :3] @ local.T).T + m[:3, 3])
            radii.append(np.full(len(local), r))
            continue
        if p.kind is ShapeKind.BOX:
            half = np.array([_num(g.x), _num(g.y), _num(g.z)]) / 2
        elif p.kind in (ShapeKind.CYLINDER, ShapeKind.CONE):
            half = np.full(3, _num(g.radius))
            a = axis_vector(g.axis)
            half[int(np.argmax(np.abs([a.x, a.y, a.z])))] = _num(g.height) / 2
        else:
            continue
        levels = [(-1.0, 0.0, 1.0) if 2 * h > SAMPLE_EDGE else (-1.0, 1.0) for h in half]
        grid = np.array([[x, y, z] for x in levels[0] for y in levels[1] for z in levels[2]])
        out.append((m[:3, :3] @ (grid * half).T).T + m[:3, 3])
        radii.append(np.zeros(len(grid)))
    if not out:
        return np.zeros((0, 3)), np.zeros(0)
    return np.concatenate(out), np.concatenate(radii)


def _palm_frames(ee: np.ndarray, rcm: np.ndarray, l_yaw2ctrl: float) -> np.ndarray:
    """The wrist's pitch link frames (C, 4, 4) for end-effector poses (C, 4, 4) of a PSM whose
    remote centre of motion is ``rcm``: at the yaw axis, x along it (the end effector's x), y
    along the palm toward the pitch axis (the closed-form IK's step 2)."""
    r = ee[:, :3, :3]
    p_yaw = ee[:, :3, 3] - l_yaw2ctrl * r[:, :, 2]
    local = np.einsum("cji,cj->ci", r, p_yaw - rcm)
    towards = -local * np.array([0.0, 1.0, 1.0])
    towards /= np.maximum(np.linalg.norm(towards, axis=1, keepdims=True), 1e-12)
    y = np.einsum("cij,cj->ci", r, towards)
    x = r[:, :, 0]
    out = np.zeros_like(ee)
    out[:, :3, 0], out[:, :3, 1], out[:, :3, 2] = x, y, np.cross(x, y)
    out[:, :3, 3], out[:, 3, 3] = p_yaw, 1.0
    return out


class ToolShape:
    """Where a PSM's tool is, as points, for any end-effector pose: the jaws and the yaw link
    move with the end effector; the wrist's pitch link with the palm (from the yaw axis toward
    the pitch axis, as the IK places it); the shaft is a cylinder from the pitch axis toward the
    remote centre of motion. Sampled once from the bodies as they are (the jaws as the task
    opens them to come onto the wire)."""

    SHAFT_CHECKED = 0.04  # m of the shaft behind the wrist that the check looks at

    def __init__(self, world, psm) -> None:
        recs = psm.art.records
        ee = psm.base_in_world() @ psm.measured_cp()
        self.rcm = psm.base_in_world()[:3, 3]
        self.l_yaw2ctrl = float(psm.kin.l_yaw2ctrlpnt)
        self.l_pitch2yaw = float(psm.kin.l_pitch2yaw)
        moving = [_primitive_points(sb) for sb in [recs[psm.arm[5]][3]] + [recs[j][3] for j in psm.jaws]]
        pts = np.concatenate([p for p, _ in moving])
        self.ee_radii = np.concatenate([r for _, r in moving])
        self.ee_pts = (invert(ee) @ np.c_[pts, np.ones(len(pts))].T).T[:, :3]
        palm = _palm_frames(ee[None], self.rcm, self.l_yaw2ctrl)[0]
        frames = psm.kin.fk_all(psm.measured_jp())
        pitch = (ee @ invert(frames[7]) @ frames[5])[:3, 3]  # on the wrist's pitch axis
        if np.dot(pitch - palm[:3, 3], palm[:3, 1]) < 0:
            # sampled with the tool drawn into its cannula (insertion under L_tool2rcm: the corpus
            # PSMs start at 0), the palm points away from the remote centre; the plan's poses
            # have it toward it (the wrist's points were 11-15 mm off, mirrored, at other poses)
            palm = palm @ np.diag([1.0, -1.0, -1.0, 1.0])
        pts, self.palm_radii = _primitive_points(recs[psm.arm[4]][3])
        self.palm_pts = (invert(palm) @ np.c_[pts, np.ones(len(pts))].T).T[:, :3]
        shaft = [p for p in collision_primitives(recs[psm.arm[3]][3].body) or [] if p.geometry.radius]
        self.shaft_radius = _num(shaft[0].geometry.radius) if shaft else 0.0
        n = int(self.SHAFT_CHECKED / 0.002) + 1
        self.along = np.linspace(0.0, self.SHAFT_CHECKED, n) if shaft else np.zeros(0)

    def points(self, ee: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World points (C, K, 3) of the tool at end-effector poses (C, 4, 4), and the radius
        of each (K,): a point's clearance is the tissue's distance less its radius."""
        e = np.einsum("cij,nj->cni", ee[:, :3, :3], self.ee_pts) + ee[:, None, :3, 3]
        palm = _palm_frames(ee, self.rcm, self.l_yaw2ctrl)
        p = np.einsum("cij,nj->cni", palm[:, :3, :3], self.palm_pts) + palm[:, None, :3, 3]
        pitch = palm[:, :3, 3] + self.l_pitch2yaw * palm[:, :3, 1]
        d = self.rcm - pitch
        d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)
        sh = pitch[:, None, :] + self.along[None, :, None] * d[:, None, :]
        radii = np.r_[self.ee_radii, self.palm_radii, np.full(len(self.along), self.shaft_radius)]
        return np.concatenate([e, p, sh], axis=1), radii


def clearances(tissue: Tissue, tool: ToolShape, ee_world: np.ndarray, limit: float) -> np.ndarray:
    """How far, m, the tool stays from the tissue at each end-effector pose (C, 4, 4), up to
    ``limit``."""
    pts, radii = tool.points(ee_world)
    return np.minimum(tissue.distances(pts, radii, ee_world[:, :3, 3].mean(axis=0)), limit)
