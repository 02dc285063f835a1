"""The World every engine answers (tasks, Gymnasium, the viewer and the CLI use only this):
what a world holds, playing for a while with a progress bar, the scene's grasp (close the jaws
of a PSM and fix what its finger ghosts or sensors detect to the tool with its constraint
actuator) and the report. A back end (runner/pybullet/, runner/mujoco/) builds the plan into
its engine and supplies ``step``, ``actuate``/``release``, ``overlapping``, ``contacts``,
``constraint_error``, ``render_camera``, the bodies' poses and the articulation's drive."""

from __future__ import annotations

import math

import numpy as np

from ..diagnostics import Diagnostic, warning
from . import stability
from .names import Registry
from .options import Options
from .plan import world_gravity


class EngineBody:
    """What every engine's body answers alike (mixed into each back end's body dataclass, which
    has ``body`` (the ADF Body) and ``mass``)."""

    @property
    def static(self) -> bool:
        return self.mass == 0.0

    @property
    def name(self) -> str:
        return self.body.name or self.body.identifier


class World:
    engine = ""
    body_type: type = object  # the engine's body class (what ``body()`` answers)
    # the engine's reading of an articulation for AMBF's solver step (its chain.py's ChainModel:
    # ``ok``, ``velocities(motors, efforts, step)``), or None
    chain_model: type | None = None
    # whether an effort-driven joint past its limits must be driven back by the runner
    # (joint_commands.JointCommands._effort): PyBullet's multibody drops a link's limits while
    # others of it are driven; MuJoCo's limits, given AMBF's rows' rates (mujoco/limits.py), hold
    hold_limits_under_efforts = True

    def _setup(self, scene, options: Options | None, gui: bool) -> None:
        """What every world holds before its engine builds the scene."""
        self.scene = scene
        self.opt = options or Options()
        self.diagnostics: list[Diagnostic] = []
        self.gui = gui
        self.dt = 1.0 / self.opt.physics_hz
        self.gravity = world_gravity(scene, self.opt)
        self.registry = Registry()
        self.bodies: list = []
        self.ghosts: list = []
        self.actuators: list = []
        self.sensors: list = []
        self.cameras: list = []
        self.articulations: list = []
        self.constraints: list = []
        self.joint_names: list[str] = []
        self.joints_made: list[tuple] = []  # (ADF joint, parent body, child body) of each joint built
        self.skipped: list[str] = []
        self.steps = 0
        self.sim_time = 0.0
        self.wall_time = 0.0
        self.watch = stability.Watch()
        self.volumes: list[dict] = []  # volumes played as iso-surface bodies
        self.not_played: list[dict] = []  # every part of the scene not played, with why
        self.ground_z = None
        self._floor_z = -math.inf
        self._chains: dict[int, object] = {}  # per articulation, its chain_model
        self._chain_stepped: dict[int, int] = {}  # per articulation, the physics step chain_velocities played
        self._ghosts_passed = False  # the ghosts have had their first collision pass (before the first step)

    def inert_joints(self) -> list[tuple]:
        """(ADF joint, parent body, child body) of each joint AMBF keeps without a constraint: an
        unknown `type` (adf-format.md §8, `JOINT TYPE NOT UNDERSTOOD`) between two bodies it finds
        (one it cannot find is skipped, as every joint is), and a joint joining a body to itself
        (AMBF makes it and it moves nothing: a box falling onto the floor with one lands within
        0.03 mm of one without), and one whose parent is static with no collision shape (it holds
        nothing: plan.holds_nothing). The runner makes nothing of them; AMBF lists them among its
        joints."""
        from ..model.semantics import joint_kind
        from .plan import holds_nothing, joint_ends

        out = []
        made = {id(r[0]) for r in self.joints_made}
        for m in self.scene.all_models():
            local = Registry()
            for sb in self.bodies:
                if getattr(sb, "model", None) is m:
                    local.items[sb.key] = sb
            ns = m.namespace or ""
            for j in m.joints:
                if id(j) in made:
                    continue
                parent, child = joint_ends(self.registry, local, ns, j)
                if parent is None or child is None:
                    continue
                if joint_kind(j.type) is None or parent is child or holds_nothing(parent.body, j):
                    out.append((j, parent, child))
        return out

    def chain_velocities(self, art, motors: dict, efforts: dict) -> np.ndarray | None:
        """The joints' velocities (by record index) one physics step of AMBF's solver leaves them
        at: the articulation as AMBF's btRigidBodies, its hinges' and sliders' locking, motor
        (``motors``: record index -> target, cfm, max impulse) and limit rows and the joints closing
        its loops solved in AMBF's ten iterations, ``efforts`` (record index -> effort) on the joints
        (runner/chain_step.py; runner/joint_commands.py). None where AMBF's bodies are not asked for
        (Options.bodies), the control step is more than one physics step, or the engine's
        chain_model cannot read the articulation."""
        if self.opt.control_substeps != 1:
            return None
        model = self.chain_of(art)
        if model is None:
            return None
        self._chain_stepped[id(art)] = self.steps  # AMBF's ghosts act on its links in the chain's step
        return model.velocities(motors, efforts, self.steps, self.chain_ghosts(art))

    def chain_contacts(self, art) -> np.ndarray | None:
        """The joints' velocities (by record index) the contacts of the physics step before gave
        ``art``, as this step's chain_velocities took them in (its bodies pushed by them before
        its rows); None where it took in none or was not played for this step."""
        model = self._chains.get(id(art))
        if model is None or not self.chain_stepped(art):
            return None
        return model.core.contact

    def chain_of(self, art):
        """The engine's chain_model of ``art`` (made once), None where AMBF's bodies are not asked
        for (Options.bodies) or it cannot read the articulation."""
        if self.chain_model is None or self.opt.bodies != "ambf":
            return None
        model = self._chains.get(id(art))
        if model is None:
            model = self._chains[id(art)] = self.chain_model(self, art)
        return model if model.ok else None

    def chain_ghosts(self, art) -> dict:
        """The bodies of ``art`` (chain index: the base 0, link k at k + 1) AMBF's ghosts act on
        before this physics step: [(contact points, the ghost parent's velocity)] each
        (ChainState.ghosted). None here; an engine that plays AMBF's ghosts gives them."""
        return {}

    def chain_stepped(self, art) -> bool:
        """Whether AMBF's solver on ``art`` (chain_velocities) was played for this physics step."""
        return self._chain_stepped.get(id(art)) == self.steps

    def _warn(self, rule, msg, obj, hint="") -> None:
        self.diagnostics.append(warning(rule, msg, getattr(obj, "source", None), hint or None))

    def body(self, text: str):
        """The body whose key ``text`` names uniquely (a suffix or pattern, as the registry finds)."""
        key, hit = self.registry.find(text)
        if key is None or not isinstance(hit, self.body_type):
            raise KeyError(f"no unique body matches {text!r}")
        return hit

    def run(self, seconds: float, progress=None) -> None:
        """Play ``seconds`` of simulated time in chunks of ~50 ms, updating ``progress``."""
        per = self.dt * self.opt.control_substeps
        total = int(round(seconds / per))
        chunk = max(1, int(0.05 / per))
        done = 0
        while done < total:
            k = min(chunk, total - done)
            self.step(k)
            done += k
            if progress is not None:
                rtf = self.sim_time / self.wall_time if self.wall_time else 0.0
                progress.update(k, suffix=f"{rtf:.2f}x real time")

    def grasp(self, psm: str, on: bool):
        """Close the jaws of ``psm`` and fix the body its finger ghosts (or a sensor) detect to the
        tool (``self.actuate``); ``on=False`` releases it and opens the jaws. Returns the grasped
        body, or None. With nothing detected, the nearest free body within 2 cm of the actuator."""
        act = next((a for a in self.actuators if psm in a.key or psm in a.parent.key), None)
        if act is None:
            raise KeyError(f"no constraint actuator for {psm!r}")
        art = act.parent.articulation
        jaws = [i for i, n in enumerate(art.joint_names) if "gripper" in n] if art is not None else []
        if not on:
            self.release(act)
            for i in jaws:
                art.targets[i] = 0.5
            if art is not None:
                art.drive()
            return None
        for i in jaws:
            art.targets[i] = 0.0
        if art is not None:
            art.drive()
        found = [b for g in self.ghosts if psm in g.key for b in self.overlapping(g)]
        found += [b for s in self.sensors if psm in s.key for b in s.sensed]
        own = {id(b) for b in self.bodies if b.articulation is not None and b.articulation is art}
        found = [b for b in found if id(b) not in own]
        if not found:
            at = (act.parent.world_matrix() @ act.location)[:3, 3]
            free = [b for b in self.bodies if not b.static and id(b) not in own]
            if not free:
                return None
            near = min(free, key=lambda b: np.linalg.norm(np.array(b.com_position()) - at))
            if np.linalg.norm(np.array(near.com_position()) - at) > 0.02:
                return None
            found = [near]
        self.actuate(act, found[0])
        return found[0]

    def contacts_among(self, bodies) -> list:
        """[(body, other body, normal force N, world point)] of the contacts any of ``bodies``
        has after the last step, the body of ``bodies`` first. A back end answers it in fewer
        engine calls than a ``contacts`` call a body (a PSM's links: one query per arm)."""
        return [(sb, other, f, at) for sb in bodies for other, f, at in self.contacts(sb)]

    def adopt(self, old) -> None:
        """Take over what ``old``, a world built from the same scene, built once and can share
        (a renderer's view of the scene), so that a world rebuilt on every reset does not build
        it again; ``old`` is closed next. Nothing to share by default."""

    # ---- the report ----------------------------------------------------------------------
    def _shapeless(self, sb) -> bool:
        """The body has nothing to collide with (it falls freely under gravity, in AMBF too)."""
        return False

    def health(self) -> dict:
        """Dynamic bodies that fell through the floor (are 10 cm below the lowest static body
        and 10 cm below where they started: an arm hanging from a static base above the others
        starts below them), move faster than 10 m/s, are NaN, or have no collision shape."""
        fell, fast, nan, shapeless = [], [], [], []
        start = getattr(self, "initial_positions", {})
        for sb in self.bodies:
            if sb.static:
                continue
            p, _, v, _ = sb.state()
            if not np.all(np.isfinite(p)) or not np.all(np.isfinite(v)):
                nan.append(sb.key)
                continue
            if self._shapeless(sb):
                shapeless.append(sb.key)
                continue
            below_start = sb.key not in start or p[2] < start[sb.key][2] - 0.1
            if math.isfinite(self._floor_z) and p[2] < self._floor_z - 0.1 and below_start:
                fell.append(sb.key)
            if np.linalg.norm(v) > 10.0:
                fast.append(sb.key)
        return {"fell_through_floor": fell, "exploded": fast, "nan": nan, "without_collision_shape": shapeless}

    def report(self) -> dict:
        """What was built and how it played (``adfkit run``'s report.json)."""
        rep = {
            "bodies": len(self.bodies),
            "skipped_bodies": self.skipped,
            "joints": len(self.joint_names),
            "multibodies": len(self.articulations),
            "constraints": len(self.constraints),
            "ghosts": len(self.ghosts),
            "sensors": len(self.sensors),
            "actuators": len(self.actuators),
            "cameras": [c.name for c in self.cameras],
            "steps": self.steps,
            "physics_hz": self.opt.physics_hz,
            "control_substeps": self.opt.control_substeps,
            "simulated_time_s": self.sim_time,
            "wall_time_s": self.wall_time,
            "real_time_factor": self.sim_time / self.wall_time if self.wall_time else None,
            "max_constraint_error_m": self.constraint_error(),
            "ground_plane_z": self.ground_z,
            **self.health(),
        }
        rep.update(self._engine_report(rep))
        rep.update(self.watch.report())
        rep["volumes"] = self.volumes
        rep["not_played"] = self.not_played
        return rep

    def _engine_report(self, rep: dict) -> dict:
        return {}
