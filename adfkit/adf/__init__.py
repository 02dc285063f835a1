"""ADF at the edge of the model: read files into it, write it back."""

from .paths import collision_mesh_path, visual_mesh_path  # noqa: F401
from .reader import load, read_file  # noqa: F401
from .scene import load_scene, parse_indices  # noqa: F401
from .writer import atomic_write_bytes, atomic_write_text, dumps, write_file  # noqa: F401
