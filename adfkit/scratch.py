"""Temporary files that no command leaves behind.

Every temporary file adfkit makes in ``$TMPDIR`` (meshes converted for an engine, a cone's hull,
a soft body's nodes, the MuJoCo engine's MJCF, a saved Bullet state) lives in one folder per
process, ``$TMPDIR/adfkit-run-<pid>-*``: removed when the command ends (``adfkit.cli`` calls
:func:`cleanup`) and at the process's exit. A file written beside its target (the atomic
writers' ``.<name>.<pid>.*.tmp``) is renamed onto the target or removed, whatever happens.
What a killed process (SIGKILL) could not remove carries its pid in its name: the next command
removes the scratch folders of processes no longer running (:func:`sweep`), and the next write
of the same target removes that target's stale temporary files (:func:`temp_beside`)."""

from __future__ import annotations

import atexit
import os
import re
import shutil
import tempfile
from pathlib import Path

PREFIX = "adfkit-run-"
_RUN = re.compile(rf"^{re.escape(PREFIX)}(\d+)-")
_current: tuple[int, Path] | None = None  # (pid, folder) of this process's scratch folder
_at_exit: int | None = None  # the pid that registered cleanup with atexit


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return pid > 0  # another user's process (or a number no pid can be)
    return True


def scratch_dir() -> Path:
    """This process's scratch folder (made on the first call, again after :func:`cleanup`)."""
    global _current, _at_exit
    pid = os.getpid()
    if _current is not None and _current[0] == pid and _current[1].is_dir():
        return _current[1]
    folder = Path(tempfile.mkdtemp(prefix=f"{PREFIX}{pid}-"))
    if _at_exit != pid:
        atexit.register(cleanup)
        _at_exit = pid
    _current = (pid, folder)
    return folder


def mkdtemp(prefix: str) -> Path:
    """A new folder in the scratch folder."""
    return Path(tempfile.mkdtemp(prefix=prefix, dir=scratch_dir()))


def temporary_directory(prefix: str) -> tempfile.TemporaryDirectory:
    """tempfile.TemporaryDirectory in the scratch folder (removed when done, or with it)."""
    return tempfile.TemporaryDirectory(prefix=prefix, dir=scratch_dir())


def cleanup() -> None:
    """Remove this process's scratch folder (what used it is done: the command returned)."""
    global _current
    if _current is not None and _current[0] == os.getpid():
        shutil.rmtree(_current[1], ignore_errors=True)
        _current = None


def sweep(root: str | os.PathLike | None = None) -> list[Path]:
    """Remove the scratch folders in ``root`` ($TMPDIR) of processes no longer running (killed
    before they could); returns what was removed. Only this user's folders are touched."""
    root = Path(root if root is not None else tempfile.gettempdir())
    removed = []
    try:
        entries = list(os.scandir(root))
    except OSError:
        return removed
    for e in entries:
        m = _RUN.match(e.name)
        if m is None or _alive(int(m.group(1))):
            continue
        try:
            if not e.is_dir(follow_symlinks=False) or e.stat(follow_symlinks=False).st_uid != os.getuid():
                continue
        except OSError:
            continue
        shutil.rmtree(e.path, ignore_errors=True)
        removed.append(Path(e.path))
    return removed


def temp_dir_beside(path: Path) -> Path:
    """mkdtemp beside ``path`` (a folder written whole, then renamed onto it), named
    ``.<name>.<pid>.*``, after removing such folders of processes no longer running."""
    _remove_stale(path, "", folders=True)
    return Path(tempfile.mkdtemp(prefix=f".{path.name}.{os.getpid()}.", dir=path.parent))


def _remove_stale(path: Path, suffix: str, folders: bool = False) -> None:
    stale = re.compile(rf"^\.{re.escape(path.name)}\.(\d+)\..*{re.escape(suffix)}$")
    try:
        entries = list(os.scandir(path.parent))
    except OSError:
        return
    for e in entries:
        m = stale.match(e.name)
        if m is None or _alive(int(m.group(1))):
            continue
        try:
            if folders and e.is_dir(follow_symlinks=False):
                shutil.rmtree(e.path, ignore_errors=True)
            elif not folders and e.is_file(follow_symlinks=False):
                os.unlink(e.path)
        except OSError:
            pass


def temp_beside(path: Path, suffix: str = ".tmp") -> tuple[int, str]:
    """mkstemp beside ``path``, named ``.<name>.<pid>.*<suffix>``, after removing such files of
    processes no longer running (a write of this target killed before its rename)."""
    _remove_stale(path, suffix)
    return tempfile.mkstemp(prefix=f".{path.name}.{os.getpid()}.", suffix=suffix, dir=path.parent)


__all__ = ["cleanup", "mkdtemp", "scratch_dir", "sweep", "temp_beside", "temp_dir_beside", "temporary_directory"]
