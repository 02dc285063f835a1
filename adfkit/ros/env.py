"""Where ROS 1 comes from: Debian's packages (``ros-core python3-rospy …``) under the system
Python 3.11, whose ``/usr/lib/python3/dist-packages`` the project's venv (CPython 3.11 too)
reads after its own packages. Nothing outside ``adfkit.ros`` calls this, so without ROS the
rest of adfkit never looks for it."""

from __future__ import annotations

import importlib
import os
import sys
from pathlib import Path

from ..diagnostics import AdfError, error

#: where Debian puts the Python 3 ROS packages (rospy, genpy, the common messages, PyKDL)
DEBIAN_DIST_PACKAGES = Path("/usr/lib/python3/dist-packages")
#: the Debian packages `make ros` installs (what `adfkit ros` and its tests need)
DEBIAN_PACKAGES = (
    "ros-core",
    "python3-rospy",
    "python3-pykdl",
    "python3-sensor-msgs",
    "python3-geometry-msgs",
    "python3-genpy",
    "python3-std-msgs",
)
INSTALL_HINT = (
    "install ROS 1 from Debian: `make ros` (as root), or `sudo apt-get install " + " ".join(DEBIAN_PACKAGES) + "`"
)


def ros_paths() -> list[str]:
    """The folders that hold ROS's Python packages on this machine (appended to sys.path, after
    the venv's own, so that no venv package is shadowed)."""
    extra = os.environ.get("ADFKIT_ROS_PYTHONPATH")
    paths = [p for p in (extra or "").split(os.pathsep) if p]
    if DEBIAN_DIST_PACKAGES.is_dir():
        paths.append(str(DEBIAN_DIST_PACKAGES))
    return paths


def ros_available() -> str | None:
    """None when rospy, genpy and the common messages import here; else why not."""
    try:
        import_ros()
    except AdfError as exc:
        return exc.diagnostics[0].message
    return None


def import_ros():
    """Import rospy (and check genpy and the common messages), making Debian's packages
    visible first; an AdfError saying what to install when they are not there."""
    for p in ros_paths():
        if p not in sys.path:
            sys.path.append(p)
    missing = []
    for mod in ("rospy", "genpy", "rosgraph", "std_msgs.msg", "geometry_msgs.msg", "sensor_msgs.msg"):
        try:
            importlib.import_module(mod)
        except ImportError as exc:
            missing.append(f"{mod} ({exc})")
    if missing:
        raise AdfError(
            error(
                "ros-missing",
                "ROS 1's Python packages are not installed here: " + "; ".join(missing),
                None,
                INSTALL_HINT,
            )
        )
    import rospy

    return rospy


def publisher(rospy, topic: str, msg_type, queue_size: int | None = None):
    """A rospy Publisher; ``queue_size`` None (the default here) writes each message on the
    caller's thread: rospy's queued publisher hands every message to a thread per subscriber
    and yields (``time.sleep(0)``) on each, ~1 ms a message on a loaded 2-core box, which a loop
    publishing at 1 kHz cannot afford (rospy warns about None; said here on purpose). Nagle's
    algorithm off, as ambf_client's own publishers have it: a state goes out at once."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SyntaxWarning)
        return rospy.Publisher(topic, msg_type, queue_size=queue_size, tcp_nodelay=True)
