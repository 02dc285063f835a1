"""`adfkit view`: a scene played live from the runner, drawn in a web browser by viser.

The viewer is a front end on the same world interface as the tasks and the CLI: it builds a
PyBullet or MuJoCo world, steps it on a thread of its own, and sends the bodies' poses to the
page. Geometry comes from the ADF model (viewer/geometry.py), so both engines look alike. The
controls (panels.py) change the world only under ``lock``.
"""

from __future__ import annotations

import socket
import threading
import time
from pathlib import Path

import numpy as np

from ..diagnostics import AdfError, Diagnostic, Severity, error
from ..runner.rotations import matrix_to_quat
from . import geometry

FRAME_S = 1 / 30  # the page is sent poses this often while playing


def _wxyz(m: np.ndarray) -> tuple:
    x, y, z, w = matrix_to_quat(m[:3, :3])
    return (float(w), float(x), float(y), float(z))


def check_port(host: str, port: int) -> None:
    """A port already taken is a clear error before the server starts."""
    with socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET, socket.SOCK_STREAM) as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind((host, port))
        except OSError as exc:
            raise AdfError(
                error(
                    "port-in-use",
                    f"cannot listen on {host}:{port}: {exc.strerror or exc}",
                    None,
                    "pick another port with --port, or stop what uses this one",
                )
            ) from None


class Viewer:
    """One scene in one viser server. ``findings`` are the scene's validation diagnostics; when
    the scene cannot be played (``world`` None) the page lists them instead."""

    def __init__(
        self,
        scene_path: Path,
        indices,
        engine: str = "pybullet",
        host: str = "127.0.0.1",
        port: int = 8080,
        episode: Path | None = None,
    ) -> None:
        self.scene_path, self.indices, self.engine = Path(scene_path), indices, engine
        self.host, self.port, self.episode_dir = host, port, episode
        self.lock = threading.RLock()
        self.world = None
        self.scene = None
        self.findings: list[Diagnostic] = []
        self.playing = False
        self.frames_sent = 0
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.body_nodes: list = []  # (sim body, frame handle)
        self.soft_nodes: list = []  # (soft body, mesh handle): vertices resent each frame
        self.ghost_nodes: list = []  # (sim ghost, frame handle)
        self.toggled: dict[str, list] = {"collision": [], "ghosts": [], "joints": [], "frustums": []}
        self.contacts = None
        self.episode = None
        self.server = None
        self.rtf = 0.0
        self.boxes: list = []  # (low, high, static) world box of each body drawn: the first view frames them
        self._textures_said: set[str] = set()
        self.camera_image = None  # the Cameras panel's image and its Draw (panels.camera_panel)
        self.draw_camera = None

    # ---- the scene --------------------------------------------------------------------------
    def load(self) -> None:
        """Validate the scene and build its world; errors are kept as findings, not raised."""
        from ..adf import load_scene
        from ..validator.engine import validate_files

        try:
            results = validate_files([(self.scene_path, None)])
            self.findings = [d for r in results for d in r.diagnostics]
        except AdfError as exc:
            self.findings = list(exc.diagnostics)
        if any(d.severity >= Severity.ERROR for d in self.findings):
            return
        try:
            self.scene = load_scene(self.scene_path, self.indices, [])
            self.world = self._make_world()
        except AdfError as exc:
            self.findings += list(exc.diagnostics)
            self.world = None

    def _make_world(self):
        from ..runner import open_world
        from ..runner.options import Options

        return open_world(self.scene, Options(renderer="auto"), engine=self.engine)

    def reset(self) -> None:
        """Build the world again from the scene (both engines, whatever was changed)."""
        with self.lock:
            if self.world is not None:
                self.world.close()
            self.world = self._make_world()
            self.update_poses()

    # ---- the page ---------------------------------------------------------------------------
    def start(self) -> str:
        """Start the server (the port checked first) and draw the scene; returns its address."""
        import viser

        check_port(self.host, self.port)
        self.server = viser.ViserServer(host=self.host, port=self.port, verbose=False)
        self.server.scene.set_up_direction("+z")
        from . import panels

        if self.world is not None:
            self._draw()
            self._initial_view()
        panels.findings_panel(self)
        if self.world is not None:
            panels.simulation_panel(self)
            panels.show_panel(self)
            panels.joints_panel(self)
            panels.psm_panel(self)
            panels.camera_panel(self)
            if self.episode_dir is not None:
                panels.episode_panel(self)
            self._thread = threading.Thread(target=self._loop, name="adfkit-view", daemon=True)
            self._thread.start()
        shown = "localhost" if self.host in ("127.0.0.1", "::1", "localhost") else self.host
        return f"http://{shown}:{self.port}"

    def _initial_view(self) -> None:
        """Open the page on every body of the scene (framing.py), looking from the side its first
        camera looks from (else from above and aside)."""
        from .framing import overview

        cam, w = self.server.initial_camera, self.world
        look = w.cameras[0].view(w) if w.cameras else None
        view = overview(self.boxes, cam.fov, look)
        if view is not None:
            eye, target, up = view
            cam.position, cam.look_at, cam.up = tuple(eye), tuple(target), tuple(up)

    def _draw(self) -> None:
        scene, w = self.server.scene, self.world
        from . import panels

        for i, sb in enumerate(w.bodies):
            frame = scene.add_frame(f"/bodies/b{i}", show_axes=False)
            surface = getattr(sb, "surface", None)  # a volume's iso-surface (runner/volumes.py)
            parts = [geometry.Part(*surface)] if surface is not None else geometry.visual_parts(sb.model, sb.body)
            self._note_missing_textures(sb)
            self._box(sb, parts)
            for k, part in enumerate(parts):
                if part.textured is not None:
                    h = scene.add_mesh_trimesh(f"/bodies/b{i}/visual{k}", part.textured)
                    h.on_click(lambda _e, sb=sb: panels.show_body(self, sb))
                    continue
                h = scene.add_mesh_simple(
                    f"/bodies/b{i}/visual{k}",
                    part.vertices,
                    part.faces,
                    color=tuple(part.colour[:3]),
                    opacity=part.colour[3] if part.colour[3] < 1 else None,
                )
                h.on_click(lambda _e, sb=sb: panels.show_body(self, sb))
            for k, part in enumerate(geometry.collision_parts(sb.model, sb.body)):
                h = scene.add_mesh_simple(
                    f"/bodies/b{i}/collision{k}",
                    part.vertices,
                    part.faces,
                    color=tuple(part.colour[:3]),
                    opacity=part.colour[3],
                    wireframe=True,
                    visible=False,
                )
                self.toggled["collision"].append(h)
            self.body_nodes.append((sb, frame))
        self._draw_soft_bodies()
        models = list(self.scene.all_models())
        for j, g in enumerate(w.ghosts):
            model = next((m for m in models if any(x is g.ghost for x in m.ghost_objects)), None)
            if model is None:
                continue
            frame = scene.add_frame(f"/ghosts/g{j}", show_axes=False, visible=False)
            for k, part in enumerate(
                geometry.visual_parts(model, g.ghost) or geometry.collision_parts(model, g.ghost, (0.2, 0.5, 1.0, 0.3))
            ):
                scene.add_mesh_simple(
                    f"/ghosts/g{j}/shape{k}", part.vertices, part.faces, color=(0.2, 0.5, 1.0), opacity=0.35
                )
            self.ghost_nodes.append((g, frame))
            self.toggled["ghosts"].append(frame)
        self._draw_joint_frames()
        self._draw_cameras()
        self.update_poses()

    def _box(self, sb, parts) -> None:
        """The world box of a body's drawn parts, for the first view's framing."""
        if not parts:
            return
        m = sb.world_matrix()
        v = np.concatenate([np.asarray(p.vertices, float) for p in parts]) @ m[:3, :3].T + m[:3, 3]
        self.boxes.append((v.min(axis=0), v.max(axis=0), sb.static))

    def _note_missing_textures(self, sb) -> None:
        """A texture a visual mesh names that is not there (the challenge's drape names one by an
        absolute path from its author's machine) is said once, in the findings and on stderr,
        however many bodies share it."""
        import sys

        from ..diagnostics import warning

        for what in geometry.missing_textures(sb.model, sb.body):
            if what in self._textures_said:
                continue
            self._textures_said.add(what)
            d = warning(
                "view-missing-texture",
                f"{sb.body.identifier}: {what} of its visual mesh not found; drawn without it (said once for "
                "every body whose mesh names it)",
                sb.body.where("mesh") or sb.body.source,
                "textures come from the mesh's own material (MTL) file: give it a path relative to that file",
            )
            self.findings.append(d)
            print(d.format(), file=sys.stderr)

    def _draw_soft_bodies(self) -> None:
        """Soft bodies as their simulation meshes, the nodes sent again with every frame."""
        soft = getattr(self.world, "soft", None)
        if soft is None:
            return
        from ..geometry.softmesh import placed_soft_mesh
        from ..runner.plan import rgba

        for n, s in enumerate(soft.items):
            try:
                tris = np.asarray(placed_soft_mesh(s.model, s.soft).triangles, dtype=np.uint32)
            except (AdfError, ValueError):
                continue
            colour = rgba(s.soft) or (0.85, 0.55, 0.5, 1.0)
            h = self.server.scene.add_mesh_simple(
                f"/soft/s{n}", s.nodes().astype(np.float32), tris, color=tuple(colour[:3]), side="double"
            )
            self.soft_nodes.append((s, h))

    def _draw_joint_frames(self) -> None:
        from ..model.semantics import body_joint_frames

        index = {id(sb.body): i for i, sb in enumerate(self.world.bodies)}
        for m in self.scene.all_models():
            for j in m.joints:
                parent = m.body(j.parent) if j.parent else None
                if parent is None or id(parent) not in index:
                    continue
                try:
                    a, _ = body_joint_frames(j, parent, m.body(j.child) if j.child else None)
                except (TypeError, ValueError, ZeroDivisionError):
                    continue
                q = a.orientation
                h = self.server.scene.add_frame(
                    f"/bodies/b{index[id(parent)]}/joint_{len(self.toggled['joints'])}",
                    axes_length=0.01,
                    axes_radius=0.0006,
                    position=tuple(a.position),
                    wxyz=(q.w, q.x, q.y, q.z),
                    visible=False,
                )
                self.toggled["joints"].append(h)

    def _draw_cameras(self) -> None:
        from ..dataset.writer import camera_to_world

        for n, cam in enumerate(self.world.cameras):
            t = camera_to_world(*cam.view(self.world))
            h = self.server.scene.add_camera_frustum(
                f"/cameras/c{n}",
                fov=float(cam.fov),
                aspect=cam.width / cam.height,
                scale=0.02,
                color=(0.9, 0.6, 0.1),
                position=tuple(t[:3, 3]),
                wxyz=_wxyz(t),
                visible=False,
            )
            self.toggled["frustums"].append(h)

    def update_poses(self) -> None:
        """Send every body's and ghost's pose (and the contacts when shown) to the page."""
        with self.lock:
            w = self.world
            if w is None or self.server is None:
                return
            for sb, frame in self.body_nodes:
                m = sb.world_matrix()
                if np.all(np.isfinite(m)):
                    frame.position, frame.wxyz = tuple(m[:3, 3]), _wxyz(m)
            for s, h in self.soft_nodes:
                h.vertices = s.nodes().astype(np.float32)
            for g, frame in self.ghost_nodes:
                if frame.visible:
                    m = w.ghost_pose(g)
                    frame.position, frame.wxyz = tuple(m[:3, 3]), _wxyz(m)
            if self.contacts is not None:
                from . import panels

                panels.draw_contacts(self)
            self.frames_sent += 1

    def _loop(self) -> None:
        while not self._stop.is_set():
            t0 = time.perf_counter()
            if self.playing and self.world is not None:
                with self.lock:
                    s0 = self.world.sim_time
                    self.world.run(FRAME_S)
                    sim = self.world.sim_time - s0
                self.update_poses()
                elapsed = time.perf_counter() - t0
                self.rtf = sim / elapsed if elapsed > 0 else 0.0
            wait = FRAME_S - (time.perf_counter() - t0)
            if wait > 0:
                self._stop.wait(wait)

    def close(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5)
        if self.server is not None:
            self.server.stop()
        with self.lock:
            if self.world is not None:
                self.world.close()
                self.world = None
