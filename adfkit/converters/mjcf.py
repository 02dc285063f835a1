"""MJCF as a converter format: ``write`` in mjcf_write.py, ``read`` in mjcf_read.py."""

from __future__ import annotations

from .mjcf_read import read
from .mjcf_write import write

__all__ = ["read", "write"]
