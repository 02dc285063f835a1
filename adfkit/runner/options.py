"""What a world is played with, for every engine (the PyBullet and MuJoCo worlds read the same
options; neither engine's module is needed to make them)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass
class Options:
    physics_hz: float = 1000.0  # internal Bullet step (AMBF: fixed 1 ms)
    control_substeps: int = 4  # physics steps per control step (springs, ghosts, drives held between)
    solver_iterations: int | None = 10  # Bullet's own default, which AMBF runs with (PyBullet raises it to 50)
    contact_threshold: float | None = None  # Bullet's contact breaking threshold; None: its default 0.02
    gravity: tuple | None = None  # override the world's
    visuals: bool = True
    # what ghost objects do to the bodies inside them (ghost_rules.GHOST_RULES): "ambf", AMBF's afGhostObject
    # (every ghost: gravity off and 0.9 of the velocity kept per step and contact point);
    # "hole-friction", the paper's F = -K·v_rel inside hole ghosts only (K: hole_friction), which the
    # suture task was built and accepted on: the default here, for the tasks; `adfkit run` and
    # `adfkit parity` play AMBF's rule unless asked otherwise
    ghosts: str = "hole-friction"
    # how the PyBullet runner plays six-dof springs and dampers (spring_forces.SpringSet): "implicit", backward
    # Euler over the control step (stable at any gain; the default here, which the tasks were built and
    # accepted on); "ambf", as AMBF's btGeneric6DofSpring2Constraint: explicit k·x + c·v at every
    # physics step, k and c capped at m/(16·dt²) and m/dt (m the joint's inertia about the axis or its
    # mass). `adfkit run` and `adfkit parity` play AMBF's unless asked otherwise. MuJoCo: "ambf" plays the
    # dampers of the springs Bullet does not cap explicitly, bounded as Bullet's rows (mujoco/spring_rows.py)
    springs: str = "implicit"
    # where the PyBullet runner puts a multibody link's collision shapes: "body", where the file puts
    # them on the body (AMBF's; the link's frame is its joint's frame, the shapes are made in it);
    # "com", as if the link's frame were the body's centre-of-mass frame, off by where the joint
    # frame sits in the body (the corpus gripper3's jaws 0.1-0.3 m off; the bundled PSMs' insertion
    # links 16-17 mm, their second jaws 1.1-1.3 mm): how the runner built links when the tasks were
    # built and accepted, the default here for them. `adfkit run` and
    # `adfkit parity` put them where the file does. MuJoCo: unused (its geoms are where the file puts them)
    link_shapes: str = "com"
    # what the PyBullet runner's bodies are (ambf_bodies.py): "pybullet", PyBullet's own (its inertia for a
    # body whose file gives none, its multibody joints capped at 100 rad/s; the default here, which the
    # tasks were built and accepted on); "ambf", AMBF's btRigidBodies: AMBF's estimated inertia (the box of
    # the collision shape's bounds) and joints as fast as AMBF's bodies may turn (π/4 a physics step).
    # `adfkit run` and `adfkit parity` play AMBF's unless asked otherwise. MuJoCo: "ambf" gives the
    # floor of a model played alone Bullet's friction, the product of the two (mujoco/contacts.py),
    # hinge, slider and spring limits Bullet's limit rows (mujoco/limits.py) and a body without
    # inertia AMBF's estimate (mujoco/inertia.py)
    bodies: str = "pybullet"
    hole_friction: float = 2.0  # K of F = -K·v_rel inside hole ghosts, N·s/m
    hole_ghost_words: tuple = ("entry", "exit", "hole")
    ground: bool = True  # a model played without a world gets a floor under it
    ground_z: float | None = None  # that floor's height; None: 1 mm under its lowest body
    # cameras (cameras.choose_renderer): "tiny" (TinyRenderer, CPU; nothing to set up, best for a
    # frame or two), "mujoco" (MuJoCo's renderer on a mirror of the scene: ~1 s to build, then
    # ~15x faster frames), "egl" (PyBullet's EGL plugin), "auto" (mujoco, else egl, else tiny)
    renderer: str = "tiny"
