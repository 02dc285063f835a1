"""ADF validator: JSON Schema with positions plus semantic rules, and its reporters."""

from .engine import FileResult, validate_file, validate_paths  # noqa: F401
from .rules import RULES, Rule  # noqa: F401
