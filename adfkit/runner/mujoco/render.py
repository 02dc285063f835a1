"""Cameras of the MuJoCo engine: the scene's ADF cameras (cameras.py reads them, stereo pairs
included) become MJCF cameras on their parent bodies and render offscreen with MuJoCo's
OpenGL renderer: RGB from one pass; depth (metres along the optical axis) and per-body
segmentation (index into world.bodies, -1 for none) from one segmentation pass.

Headless OpenGL: MUJOCO_GL when set, else EGL, then OSMesa. When none opens, the cameras
are listed but render() raises CameraUnavailable with the reason (world.camera_problem).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import mujoco
import numpy as np

from ..cameras import Camera
from ..glcontext import gl_context_class as _gl_context_class
from ..rotations import invert, matrix_to_quat, pose_to_matrix


class CameraUnavailable(RuntimeError):
    """No headless OpenGL context could be made for MuJoCo's renderer."""


@dataclass(eq=False)
class MjCamera(Camera):
    """An ADF camera (runner/cameras.py) placed as an MJCF camera: the same interface as the
    PyBullet world's cameras (``view``, ``intrinsics``, ``render``; ``dataclasses.replace``
    gives a copy with another image size), its ``parent`` the MuJoCo body and ``cam_id`` the
    MJCF camera it is drawn from."""

    world: object = None
    cam_id: int = -1

    @classmethod
    def placed(cls, world, sim_camera: Camera, cam_id: int) -> MjCamera:
        parent = world._by_plan.get(id(sim_camera.parent)) if sim_camera.parent is not None else None
        fields = {f.name: getattr(sim_camera, f.name) for f in dataclasses.fields(Camera)}
        return cls(**{**fields, "parent": parent}, world=world, cam_id=cam_id)

    def render(self, world=None, rgb_only: bool = False) -> dict:
        """{'rgb': H×W×3 uint8, 'depth': H×W float32 m (inf where nothing), 'segmentation': H×W int32}."""
        return self.world._renderer().render(self, rgb_only)


class _Renderer:
    def __init__(self, world):
        cls, why = _gl_context_class()
        if cls is None:
            raise CameraUnavailable(
                f"no headless OpenGL for MuJoCo's renderer ({why}); install libegl1 "
                "(with a GPU driver or Mesa) or libosmesa6, or set MUJOCO_GL"
            )
        m = world.model
        self.world = world
        w, h = m.vis.global_.offwidth, m.vis.global_.offheight
        try:
            self.gl = cls(w, h)
            self.gl.make_current()
            self.ctx = mujoco.MjrContext(m, mujoco.mjtFontScale.mjFONTSCALE_100)
        except Exception as e:
            raise CameraUnavailable(f"MuJoCo's renderer could not start: {type(e).__name__}: {e}") from e
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self.ctx)
        self.scene = mujoco.MjvScene(m, maxgeom=max(1000, 2 * m.ngeom))
        self.opt = mujoco.MjvOption()
        self.pert = mujoco.MjvPerturb()
        self.cam = mujoco.MjvCamera()
        self.cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
        self.near = m.vis.map.znear * m.stat.extent
        self.far = m.vis.map.zfar * m.stat.extent

    def render(self, c: MjCamera, rgb_only: bool = False) -> dict:
        m, d = self.world.model, self.world.data
        self.gl.make_current()
        self.cam.fixedcamid = c.cam_id
        scn = self.scene
        mujoco.mjv_updateScene(m, d, self.opt, self.pert, self.cam, mujoco.mjtCatBit.mjCAT_ALL, scn)
        rect = mujoco.MjrRect(0, 0, c.width, c.height)
        rgb = np.empty((c.height, c.width, 3), dtype=np.uint8)
        scn.flags[mujoco.mjtRndFlag.mjRND_SEGMENT] = False
        scn.flags[mujoco.mjtRndFlag.mjRND_IDCOLOR] = False
        mujoco.mjr_render(rect, scn, self.ctx)
        mujoco.mjr_readPixels(rgb, None, rect, self.ctx)
        if rgb_only:  # a picture: no second (segmentation) pass
            return {"rgb": rgb[::-1].copy()}
        ids = np.empty((c.height, c.width, 3), dtype=np.uint8)
        z = np.empty((c.height, c.width), dtype=np.float32)
        scn.flags[mujoco.mjtRndFlag.mjRND_SEGMENT] = True
        scn.flags[mujoco.mjtRndFlag.mjRND_IDCOLOR] = True
        mujoco.mjr_render(rect, scn, self.ctx)
        mujoco.mjr_readPixels(ids, z, rect, self.ctx)
        scn.flags[mujoco.mjtRndFlag.mjRND_SEGMENT] = False
        scn.flags[mujoco.mjtRndFlag.mjRND_IDCOLOR] = False
        # the depth buffer back to metres along the optical axis (reversed Z as mujoco.Renderer),
        # in float64 as before; every array turned upright (OpenGL's rows run bottom-up) by the
        # copy that makes it anyway
        zf, zn = np.float32(self.far), np.float32(self.near)
        z64 = z[::-1].astype(np.float64)
        if self.ctx.readDepthMap == mujoco.mjtDepthMap.mjDEPTH_ZEROFAR:
            cc = np.float32(-0.5) * (-(zf + zn) / (zf - zn)) - np.float32(0.5)
            dc = np.float32(-0.5) * (-(np.float32(2) * zf * zn) / (zf - zn))
            z64 += cc
            np.divide(dc, z64, out=z64)
        else:  # 0 at the near plane, 1 at the far one
            z64 = zn * zf / (zf - z64 * (zf - zn))
        depth = z64.astype(np.float32)
        # segment ids: geom index + 1 in the red, green and blue bytes (0: nothing); with fewer
        # than 255 geoms drawn only the red byte is ever set
        up = ids[::-1]
        if scn.ngeom < 255:
            seg = up[..., 0]
        else:
            seg = up[..., 0].astype(np.int32) | (up[..., 1].astype(np.int32) << 8) | (up[..., 2].astype(np.int32) << 16)
            np.minimum(seg, scn.ngeom, out=seg)
        lut = np.full(max(scn.ngeom + 1, 256), -1, dtype=np.int32)
        labels = self.world._geom_label
        soft = {s.fid: len(self.world.bodies) + k for k, s in enumerate(getattr(self.world.soft, "items", None) or [])}
        for n in range(scn.ngeom):
            g = scn.geoms[n]
            if g.segid >= 0 and g.objtype == mujoco.mjtObj.mjOBJ_GEOM:
                lut[g.segid + 1] = labels[g.objid]
            elif g.segid >= 0 and g.objtype == mujoco.mjtObj.mjOBJ_FLEX:  # soft body k: after the bodies
                lut[g.segid + 1] = soft.get(g.objid, -1)
        lut[scn.ngeom + 1 :] = lut[scn.ngeom]  # an id past the last geom reads as the last (as clamped before)
        segmentation = np.take(lut, seg)
        depth[seg == 0] = np.inf
        return {"rgb": rgb[::-1].copy(), "depth": depth, "segmentation": segmentation}

    def close(self) -> None:
        try:
            self.ctx.free()
            self.gl.free()
        except Exception:
            pass


class _Pending:
    def __init__(self, sims, ids):
        self.sims, self.ids = sims, ids

    def finish(self, world) -> list[MjCamera]:
        m = world.model
        if self.sims:
            near = min(c.near for c in self.sims)
            far = max(c.far for c in self.sims)
            m.vis.map.znear = near / m.stat.extent
            m.vis.map.zfar = far / m.stat.extent
        return [
            MjCamera.placed(world, c, mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_CAMERA, n))
            for c, n in zip(self.sims, self.ids)
        ]


def prepare_cameras(world, plan) -> _Pending:
    """Add an MJCF camera per ADF camera (two for a stereo pair) to the spec."""
    from ..cameras import build_cameras

    sims = build_cameras(world)
    spec = plan.spec
    names = []
    maxw, maxh = 1, 1
    for n, c in enumerate(sims):
        if c.parent is not None:
            to_link = invert(pose_to_matrix(c.parent.link.frame_in_body))
            el = spec.worldbody if c.parent.mjname == "world" else spec.body(c.parent.mjname)
        else:
            to_link, el = np.eye(4), spec.worldbody
        r, t = to_link[:3, :3], to_link[:3, 3]
        eye, target, up = r @ c.eye + t, r @ c.target + t, r @ c.up
        fwd = target - eye
        fwd /= np.linalg.norm(fwd) or 1.0
        right = np.cross(fwd, up)
        right /= np.linalg.norm(right) or 1.0
        eye = eye + c.eye_offset * right
        y = np.cross(right, fwd)
        name = f"adfkit-camera{n}:{c.name}"
        q = matrix_to_quat(np.column_stack([right, y, -fwd]))
        el.add_camera(
            name=name, pos=eye, quat=[q[3], q[0], q[1], q[2]], fovy=math.degrees(c.fov), resolution=[c.width, c.height]
        )
        names.append(name)
        maxw, maxh = max(maxw, c.width), max(maxh, c.height)
    # no multisampling: it would blend the segmentation pass's id colours at edges (and it
    # doubles the cost of a software-rendered frame)
    spec.visual.quality.offsamples = 0
    spec.visual.global_.offwidth = max(maxw, 640)
    spec.visual.global_.offheight = max(maxh, 480)
    return _Pending(sims, names)
