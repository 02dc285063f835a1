"""Builders that author the sample scenes from parameters (the project's own scenes)."""
from .suturing_pad import SuturingPadParams, build_suturing_pad, write_suturing_pad  # noqa: F401

BUILDERS = {"suturing-pad": write_suturing_pad}
from .soft_phantom import write_soft_phantom as _soft_phantom; BUILDERS["soft-phantom"] = _soft_phantom  # noqa: E402,E702
