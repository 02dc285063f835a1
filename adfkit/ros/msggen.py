"""AMBF's messages (``ambf_msgs``) as a Python package, generated the way catkin would, without
a catkin workspace: genpy's ``genmsg_py.py`` over the ``.msg`` files, with the definitions of
the std_msgs and geometry_msgs types they use taken from the installed Debian message
packages themselves (each generated class carries its full text; Debian ships no ``.msg``
files). The package is written once per definition text into a cache folder and put on
``sys.path``; identical text gives identical MD5 sums, so a client generated from AMBF's own
files talks to it."""

from __future__ import annotations

import hashlib
import importlib
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from ..diagnostics import AdfError, error
from .env import import_ros, ros_paths

#: the ambf_msgs definitions shipped with adfkit (unmodified from AMBF 2.0, see NOTICE.md)
BUNDLED = Path(__file__).parent / "ambf_msgs"
GENMSG_PY = Path("/usr/lib/genpy/genmsg_py.py")
SEPARATOR = "=" * 80 + "\n"


def cache_root() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "adfkit" / "ros"


def _dependency_texts() -> dict[str, str]:
    """'pkg/Type' -> its own .msg text, for every std_msgs / geometry_msgs type reachable from
    the ones ambf_msgs names, read from the installed classes' ``_full_text``."""
    import geometry_msgs.msg as geometry
    import std_msgs.msg as std

    out: dict[str, str] = {}
    for cls in (std.Header, std.String, std.Empty, geometry.Pose, geometry.Wrench, geometry.Twist, geometry.Point):
        chunks = cls._full_text.split(SEPARATOR)
        out[cls._type] = chunks[0]
        for chunk in chunks[1:]:
            head, _, body = chunk.partition("\n")
            out.setdefault(head.removeprefix("MSG: ").strip(), body)
    return out


def generate(msg_dir: Path, out_root: Path, package: str = "ambf_msgs") -> Path:
    """Generate ``package`` from the .msg files in ``msg_dir`` under ``out_root`` with genpy's
    genmsg_py.py (the script catkin runs). Returns ``out_root`` (to put on sys.path)."""
    import_ros()
    files = sorted(str(p) for p in Path(msg_dir).glob("*.msg"))
    if not files:
        raise AdfError(error("ros-msgs", f"no .msg files in {msg_dir}", None, "give AMBF's ambf_msgs/msg folder"))
    if not GENMSG_PY.is_file():
        raise AdfError(error("ros-missing", f"{GENMSG_PY} not found", None, "install python3-genpy (make ros)"))
    with tempfile.TemporaryDirectory() as inc:
        for name, text in _dependency_texts().items():
            pkg, typ = name.split("/")
            (Path(inc) / pkg).mkdir(exist_ok=True)
            (Path(inc) / pkg / f"{typ}.msg").write_text(text)
        out = Path(out_root) / package / "msg"
        out.mkdir(parents=True, exist_ok=True)
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(ros_paths()))
        base = [sys.executable, str(GENMSG_PY)]
        includes = [f"-I{package}:{msg_dir}", f"-Istd_msgs:{inc}/std_msgs", f"-Igeometry_msgs:{inc}/geometry_msgs"]
        for cmd in (base + ["-p", package, *includes, "-o", str(out), *files], base + ["--initpy", "-o", str(out)]):
            done = subprocess.run(cmd, env=env, capture_output=True, text=True)
            if done.returncode:
                raise AdfError(
                    error("ros-msgs", f"genmsg_py.py failed on {msg_dir}: {done.stderr.strip()[-400:]}", None, None)
                )
    (Path(out_root) / package / "__init__.py").write_text("")
    return Path(out_root)


def ensure(msg_dir: Path = BUNDLED, package: str = "ambf_msgs") -> Path:
    """The generated package for ``msg_dir`` (made on first use in the cache, keyed by the
    definitions' text), on sys.path, imported. Returns the folder put on sys.path."""
    digest = hashlib.sha256()
    for p in sorted(Path(msg_dir).glob("*.msg")):
        digest.update(p.name.encode() + b"\0" + p.read_bytes())
    root = cache_root() / f"{package}-{digest.hexdigest()[:16]}"
    if not (root / package / "msg" / "__init__.py").is_file():
        tmp = Path(tempfile.mkdtemp(prefix=f"{package}-", dir=_mkdir(cache_root())))
        generate(Path(msg_dir), tmp, package)
        try:
            tmp.rename(root)
        except OSError:  # another process made it first
            pass
    if str(root) not in sys.path:
        sys.path.insert(0, str(root))
    importlib.import_module(f"{package}.msg")
    return root


def _mkdir(p: Path) -> Path:
    p.mkdir(parents=True, exist_ok=True)
    return p
