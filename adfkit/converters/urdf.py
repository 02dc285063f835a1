"""URDF as a converter format: ``write`` in urdf_write.py, ``read`` in urdf_read.py (see
format-mapping.md). The helpers the MJCF writer shares are re-exported here."""

from __future__ import annotations

from .urdf_read import from_urdf, read
from .urdf_write import (  # noqa: F401 - shared with the MJCF modules
    _AXIS_TO_Z,
    _BODY_ONLY,
    INITIAL_VALUE_TOLERANCE,
    _joint_name,
    _link_name,
    _material,
    _num,
    _unique,
    _vec,
    to_urdf,
    write,
)

__all__ = ["read", "write", "to_urdf", "from_urdf"]
