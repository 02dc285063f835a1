"""The MuJoCo back end: the plan built as an MjSpec (build.py), compiled and read into the World
interface (world.py, assemble.py, interact.py), drawn by MuJoCo's renderer (render.py), and
the mirror that draws another engine's world with it (mirror.py)."""
