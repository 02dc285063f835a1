"""The viewer's side panels: findings, simulation controls, what to show, a slider per joint,
a PSM's jaw and Cartesian target, the cameras' images, a body's facts on click, and the replay
of a recorded suture. Each control changes the world under the viewer's lock."""

from __future__ import annotations

import math

import numpy as np

from ..diagnostics import AdfError, Severity


def findings_panel(v) -> None:
    gui = v.server.gui
    with gui.add_folder("Findings", expand_by_default=v.world is None):
        if not v.findings:
            gui.add_markdown("`adfkit validate`: no findings")
            return
        errors = sum(d.severity >= Severity.ERROR for d in v.findings)
        head = (
            f"**The scene cannot be played: {errors} error(s).**"
            if v.world is None
            else f"{len(v.findings)} finding(s)"
        )
        lines = [head, ""] + [f"- `{d.location}` **{d.severity}[{d.rule}]** {d.message}" for d in v.findings[:60]]
        gui.add_markdown("\n".join(lines))


def simulation_panel(v) -> None:
    gui = v.server.gui
    with gui.add_folder("Simulation"):
        play = gui.add_button("Play", icon=None)
        step = gui.add_button("Step")
        reset = gui.add_button("Reset")
        v.status = gui.add_markdown(_status(v))

    @play.on_click
    def _(_e) -> None:
        v.playing = not v.playing
        play.label = "Pause" if v.playing else "Play"

    @step.on_click
    def _(_e) -> None:
        with v.lock:
            v.world.step(1)
        v.update_poses()
        v.status.content = _status(v)

    @reset.on_click
    def _(_e) -> None:
        v.playing = False
        play.label = "Play"
        v.reset()
        v.status.content = _status(v)

    def tick() -> None:  # refresh the status line while playing
        if v.world is not None:
            v.status.content = _status(v)

    v.status_tick = tick


def _status(v) -> str:
    w = v.world
    return (
        f"t = {w.sim_time:.3f} s · {v.rtf:.2f}x real time · {len(w.bodies)} bodies · {v.engine}"
        if w is not None
        else "no world"
    )


def show_panel(v) -> None:
    gui = v.server.gui
    with gui.add_folder("Show"):
        boxes = {
            "collision": gui.add_checkbox("Collision shapes", False),
            "ghosts": gui.add_checkbox("Ghost objects", False),
            "joints": gui.add_checkbox("Joint frames and axes", False),
            "frustums": gui.add_checkbox("Camera frustums", False),
        }
        contacts = gui.add_checkbox("Contact points", False)
    for name, box in boxes.items():

        def flip(_e, name=name, box=box) -> None:
            for h in v.toggled[name]:
                h.visible = box.value
            v.update_poses()

        box.on_update(flip)

    @contacts.on_update
    def _(_e) -> None:
        if contacts.value:
            v.contacts = v.server.scene.add_point_cloud(
                "/contacts", np.zeros((1, 3), np.float32), colors=(1.0, 0.1, 0.1), point_size=0.003
            )
            v.update_poses()
        elif v.contacts is not None:
            v.contacts.remove()
            v.contacts = None


def contact_points(world) -> np.ndarray:
    """World positions of the contacts now, in either engine."""
    if getattr(world, "engine", "pybullet") == "mujoco":
        d = world.data
        return np.array([d.contact[i].pos for i in range(d.ncon)], dtype=np.float32).reshape(-1, 3)
    import pybullet as pb

    pts = pb.getContactPoints(physicsClientId=world.cid)
    return np.array([p[5] for p in pts], dtype=np.float32).reshape(-1, 3)


def draw_contacts(v) -> None:
    pts = contact_points(v.world)
    v.contacts.points = pts if len(pts) else np.full((1, 3), np.nan, np.float32)


def joints_panel(v) -> None:
    """A slider per joint of each multibody: the joint is put there and its motor holds it."""
    from ..model.semantics import JointKind

    gui = v.server.gui
    arts = list(getattr(v.world, "articulations", []))
    if not arts:
        return
    with gui.add_folder("Joints", expand_by_default=False):
        for art in arts:
            with gui.add_folder(short_key(art.root.key), expand_by_default=False):
                q, _ = v.world.joint_state(art, list(range(len(art.joint_names))))
                for k, (jname, kind) in enumerate(zip(art.joint_names, art.kinds)):
                    if kind not in (JointKind.REVOLUTE, JointKind.PRISMATIC):
                        continue
                    lim = art.records[k][0].joint_limits
                    span = math.pi if kind is JointKind.REVOLUTE else 0.1
                    lo = lim.low if lim is not None and lim.low is not None else -span
                    hi = lim.high if lim is not None and lim.high is not None else span
                    if not lo < hi:
                        lo, hi = -span, span
                    value = float(np.clip(q[k], lo, hi))
                    s = gui.add_slider(
                        jname.removeprefix("JOINT "),
                        min=float(lo),
                        max=float(hi),
                        step=(hi - lo) / 200,
                        initial_value=value,
                    )
                    s.on_update(lambda _e, art=art, k=k, s=s: _set_joint(v, art, k, s.value))


def short_key(key: str) -> str:
    """A body's key as a person reads it: its namespace's last part and its name
    ('/ambf/env/psm1/BODY base link simple' -> 'psm1/base link simple')."""
    parts = [p for p in key.replace("BODY ", "").split("/") if p]
    return "/".join(parts[-2:]) if parts else key


def _set_joint(v, art, k: int, value: float) -> None:
    with v.lock:
        v.world.reset_joints(art, [k], [value])
        art.targets[k] = value
        art.drive()
    v.update_poses()


def psm_panel(v) -> None:
    """For each PSM the scene has: its jaw and a Cartesian target through the closed-form IK."""
    from ..runner.psm import PSM

    gui = v.server.gui
    for name in ("psm1", "psm2"):
        try:
            with v.lock:
                psm = PSM(v.world, name)
        except (KeyError, ValueError, StopIteration, IndexError):
            continue
        with gui.add_folder(f"PSM {name}", expand_by_default=False):
            ee = psm.measured_cp()
            target = gui.add_vector3(
                "Target (m, base frame)", initial_value=tuple(float(x) for x in ee[:3, 3]), step=0.001
            )
            go = gui.add_button("Move (IK)")
            jaw = gui.add_slider("Jaw (rad)", min=0.0, max=1.0, step=0.01, initial_value=0.5)
            note = gui.add_markdown("")

        def move(_e, psm=psm, target=target, note=note) -> None:
            pose = psm.measured_cp()
            pose[:3, 3] = np.asarray(target.value, dtype=float)
            try:
                with v.lock:
                    psm.reach(pose, jump=True)
                note.content = "reached"
            except ValueError as exc:
                note.content = f"out of reach: {exc}"
            v.update_poses()

        go.on_click(move)

        def set_jaw(_e, psm=psm, jaw=jaw) -> None:
            with v.lock:
                psm.servo_jaw(jaw.value)

        jaw.on_update(set_jaw)


def camera_panel(v) -> None:
    """The scene's cameras' images: RGB, depth or segmentation, drawn on demand."""
    cams = list(v.world.cameras)
    if not cams:
        return
    gui = v.server.gui
    with gui.add_folder("Cameras", expand_by_default=False):
        which = gui.add_dropdown("Camera", tuple(c.name for c in cams), initial_value=cams[0].name)
        mode = gui.add_dropdown("Image", ("RGB", "Depth", "Segmentation"), initial_value="RGB")
        draw = gui.add_button("Draw")
        image = gui.add_image(np.zeros((48, 64, 3), np.uint8), label="camera")

    def render(_e=None) -> None:
        from ..dataset.colors import colourise

        cam = next(c for c in cams if c.name == which.value)
        try:
            with v.lock:
                frame = cam.render(v.world)
        except Exception as exc:  # noqa: BLE001 - a renderer that cannot start: said on the page
            image.label = f"no image: {type(exc).__name__}: {exc}"
            return
        if mode.value == "RGB":
            img = frame["rgb"]
        elif mode.value == "Depth":
            d = np.asarray(frame["depth"], dtype=float)
            seen = np.isfinite(d)
            lo, hi = (d[seen].min(), d[seen].max()) if seen.any() else (0.0, 1.0)
            grey = np.where(seen, 255 * (1 - (d - lo) / max(hi - lo, 1e-9)), 0).astype(np.uint8)
            img = np.repeat(grey[..., None], 3, axis=2)
        else:
            img = colourise(np.asarray(frame["segmentation"]))
        image.image = img
        image.label = f"{cam.name} · {mode.value} · t = {v.world.sim_time:.2f} s"

    draw.on_click(render)
    v.camera_image, v.draw_camera = image, render  # what the Draw button shows, and draws


def show_body(v, sb) -> None:
    """A clicked body's ADF facts in the page: name, file and line, mass, inertia."""
    b = sb.body
    where = b.where() if hasattr(b, "where") else None
    inertia = b.inertia
    text = f"**{b.identifier}** ({sb.key})\n\n- file: `{where}`\n- mass: {sb.mass:g} kg" + (
        f"\n- inertia: ix {inertia.ix:g}, iy {inertia.iy:g}, iz {inertia.iz:g} kg·m²"
        if inertia is not None and None not in (inertia.ix, inertia.iy, inertia.iz)
        else "\n- inertia: estimated (not in the file)"
    )
    if getattr(v, "selected", None) is None:
        v.selected = v.server.gui.add_markdown(text)
    else:
        v.selected.content = text


def episode_panel(v) -> None:
    """Replay a recorded suture: a timeline slider, the phase and the per-pair verdicts."""
    from .episode import load_episode

    gui = v.server.gui
    try:
        ep = load_episode(v.episode_dir)
    except AdfError as exc:
        with gui.add_folder("Episode"):
            gui.add_markdown("\n".join(f"- {d}" for d in exc.diagnostics))
        return
    v.episode = ep
    with gui.add_folder("Episode"):
        timeline = gui.add_slider("Frame", min=0, max=max(1, len(ep.frames) - 1), step=1, initial_value=0)
        phase = gui.add_markdown("")
        gui.add_markdown(ep.verdicts_markdown())

    def show(_e=None) -> None:
        f = ep.frames[int(timeline.value)]
        v.playing = False
        apply_frame(v, f)
        phase.content = f"t = {f.time_s:.2f} s · phase **{f.phase or '-'}** · step {f.step}"

    timeline.on_update(show)
    show()


def apply_frame(v, f) -> None:
    """Put the world in a recorded frame's state: the needle's pose, each PSM's joints and jaw."""
    from ..runner.psm import PSM

    with v.lock:
        w = v.world
        if f.needle is not None:
            try:
                w.place_body(w.body("Needle"), np.asarray(f.needle))
            except (AttributeError, KeyError, ValueError, StopIteration):
                pass
        for name, state in f.psms.items():
            try:
                cache = v.__dict__.setdefault("_psms", {})
                psm = cache.get(name) or cache.setdefault(name, PSM(w, name))
                if state.get("jp") is not None:
                    psm.reset_jp(np.asarray(state["jp"], dtype=float))
                if state.get("jaw") is not None:
                    psm.servo_jaw(float(state["jaw"]))
            except (KeyError, ValueError, StopIteration, IndexError):
                continue
    v.update_poses()
