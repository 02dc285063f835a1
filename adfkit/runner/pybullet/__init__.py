"""The PyBullet back end (the reference runner): the plan built as multibodies, maximal-coordinate
bodies, constraints and per-step forces (assemble.py, articulation.py, joints.py, spring_forces.py, shapes.py,
softbodies.py, volumes.py), stepped and read into the World interface (world.py, interact.py,
state.py), drawn by TinyRenderer or PyBullet's EGL plugin (cameras.py, egl.py)."""
