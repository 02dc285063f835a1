"""The PyBullet world's cameras drawn by MuJoCo's renderer (``Options(renderer="mujoco")``,
``adfkit run --renderer mujoco``).

The scene is built once more as the MuJoCo engine builds it (runner/mj: the same meshes,
colours, textures, cameras and lights, stereo pairs included), without stepping it: before each picture
every MuJoCo body is put where PyBullet has the same ADF body (matched by key), the geoms',
cameras' and lights' world poses follow from their fixed offsets on their bodies (numpy, no
kinematics), and MuJoCo's offscreen renderer draws RGB, depth and per-body segmentation
(labels are indices into the PyBullet world's ``bodies``). A stereo 640×480 RGB + depth +
segmentation frame of the suturing set costs ~30 ms on the 2-core box's software OpenGL,
against ~0.5 s with TinyRenderer; building the view costs ~1 s once.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..rotations import quat_to_matrix


def _wxyz_to_matrix(q: np.ndarray) -> np.ndarray:
    return quat_to_matrix(np.column_stack([q[:, 1], q[:, 2], q[:, 3], q[:, 0]]))


class MjMirror:
    def __init__(self, world) -> None:
        from .world import MujocoWorld

        self.world = world
        opt = dataclasses.replace(world.opt, renderer="tiny")
        self.mj = mj = MujocoWorld(world.scene, opt, sleep=False)
        m = mj.model
        sim_index = {sb.key: i for i, sb in enumerate(world.bodies)}
        matched = [(mb, sim_index[mb.key]) for mb in mj.bodies if mb.id > 0 and mb.key in sim_index]
        label = np.full(m.ngeom, -1, dtype=np.int32)  # segmentation labels: PyBullet's body indices
        for mb, i in matched:
            label[m.geom_bodyid == mb.id] = i
        mj._geom_label = label
        self._geom_body = np.array(m.geom_bodyid, dtype=int)
        self._geom_pos = np.array(m.geom_pos)
        self._geom_rot = _wxyz_to_matrix(np.array(m.geom_quat))
        self._cam_body = np.array(m.cam_bodyid, dtype=int)
        self._cam_pos = np.array(m.cam_pos)
        self._cam_rot = _wxyz_to_matrix(np.array(m.cam_quat))
        self._light_body = np.array(m.light_bodyid, dtype=int)
        self._light_pos = np.array(m.light_pos)
        self._light_dir = np.array(m.light_dir)
        self.cameras = list(mj.cameras)
        if [c.name for c in self.cameras] != [c.name for c in world.cameras]:
            raise ValueError(
                "MuJoCo's build placed other cameras than PyBullet's "
                f"({[c.name for c in self.cameras]} against {[c.name for c in world.cameras]})"
            )
        # MuJoCo body id -> (PyBullet SimBody, MuJoCo link frame in the ADF body frame), for the
        # bodies something is drawn on (only their poses are read from PyBullet)
        drawn = set(self._geom_body.tolist()) | set(self._cam_body.tolist()) | set(self._light_body.tolist())
        self._drawn = [(mb.id, i, mb.key, mb.link_in_body) for mb, i in matched if mb.id in drawn]
        self.pairs = [(bid, world.bodies[i], link_in_body) for bid, i, _, link_in_body in self._drawn]

    def rebind(self, world) -> None:
        """Draw ``world`` from now on: a PyBullet world built afresh from the same scene (the same
        bodies in the same order, as a Gymnasium reset builds it), so the view is not built again."""
        keys = [sb.key for sb in world.bodies]
        if any(i >= len(keys) or keys[i] != key for _, i, key, _ in self._drawn) or [c.name for c in world.cameras] != [
            c.name for c in self.cameras
        ]:
            raise ValueError("the world has other bodies or cameras than the one this view was built for")
        self.world = world
        self.pairs = [(bid, world.bodies[i], link_in_body) for bid, i, _, link_in_body in self._drawn]

    def _sync(self) -> None:
        """MuJoCo's drawn frames from PyBullet's bodies."""
        d = self.mj.data
        xpos, xmat = np.array(d.xpos), np.array(d.xmat).reshape(-1, 3, 3)
        for bid, sb, link_in_body in self.pairs:
            t = sb.world_matrix() @ link_in_body
            xpos[bid], xmat[bid] = t[:3, 3], t[:3, :3]
        d.xpos[:] = xpos
        d.xmat[:] = xmat.reshape(-1, 9)

        def on(bodies, local):  # points (or directions) fixed on their bodies, in the world
            return np.einsum("nij,nj->ni", xmat[bodies], local)

        gb, cb, lb = self._geom_body, self._cam_body, self._light_body
        d.geom_xpos[:] = xpos[gb] + on(gb, self._geom_pos)
        d.geom_xmat[:] = (xmat[gb] @ self._geom_rot).reshape(-1, 9)
        if cb.size:
            d.cam_xpos[:] = xpos[cb] + on(cb, self._cam_pos)
            d.cam_xmat[:] = (xmat[cb] @ self._cam_rot).reshape(-1, 9)
        if lb.size:
            d.light_xpos[:] = xpos[lb] + on(lb, self._light_pos)
            d.light_xdir[:] = on(lb, self._light_dir)

    def render(self, camera, rgb_only: bool = False) -> dict:
        """The PyBullet world's ``camera`` now: one of ``world.cameras`` or a copy of one with
        another image size (the Gymnasium environments resize them)."""
        import copy

        sims = self.world.cameras
        index = next((i for i, c in enumerate(sims) if c is camera), None)
        if index is None:
            index = next(
                (
                    i
                    for i, c in enumerate(sims)
                    if (c.key, c.name, c.eye_offset) == (camera.key, camera.name, camera.eye_offset)
                ),
                None,
            )
        if index is None:
            raise ValueError(f"camera {camera.name!r} is not one of the scene's")
        cam = self.cameras[index]
        if (cam.width, cam.height) != (camera.width, camera.height):
            g = self.mj.model.vis.global_
            if camera.width > g.offwidth or camera.height > g.offheight:
                raise ValueError(
                    f"{camera.width}x{camera.height} is larger than the offscreen buffer ({g.offwidth}x{g.offheight})"
                )
            cam = copy.copy(cam)
            cam.width, cam.height = camera.width, camera.height
        self._sync()
        return self.mj._renderer().render(cam, rgb_only)

    def close(self) -> None:
        self.mj.close()
