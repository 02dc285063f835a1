"""The scene model in the middle of adfkit: plain dataclasses, no I/O.

Fields mirror ADF keys (see :mod:`adfkit.model.spec`); ``None`` means "not written" and
``adfkit.model.defaults`` gives what AMBF uses then.
"""

from .common import *  # noqa: F401,F403
from .files import (  # noqa: F401
    FILE_KINDS,
    AdfFile,
    ButtonMapping,
    Colors,
    Enclosure,
    HapticGain,
    InputDevice,
    InputDevices,
    Launch,
    ModelFile,
    Scene,
    Skybox,
    World,
)
from .objects import *  # noqa: F401,F403
from .pose import IDENTITY, Pose, Quat, Vec3, quat_to_rpy, rpy_to_quat  # noqa: F401
from .spec import Node, Obj, adf_fields, adf_keys  # noqa: F401
