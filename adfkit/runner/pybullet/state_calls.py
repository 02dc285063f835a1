"""Many bodies' base states read, and their torques and forces applied, in one call each
(state_calls.c, built with the system's C compiler the first time a world asks for it).

PyBullet has no batched call for separate bodies: under AMBF's springs (Options.springs "ambf") the
spring set reads each of the corpus suturing set's 49 free bodies twice and pushes 56 of them at
every physics step, ~150 Python calls of ~1 µs. The C file makes the same requests of the same
physics server through PyBullet's own C API, one request a body, so every number read or applied
is the one PyBullet's Python calls give: the trajectory stays the same to the bit. The same file
evaluates AMBF's springs whole (spring_c.py), which is not numpy's rounding.

Where no C compiler is found, the build fails, PyBullet refuses the plugin, the client is not a
DIRECT one (a GUI server runs in a thread of its own) or ``ADFKIT_NO_C`` is set, ``for_client``
answers None and the runner makes the Python calls (the same numbers, slower; numpy's springs).
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import pybullet as pb

SOURCE = Path(__file__).with_name("state_calls.c")
_lib: ctypes.CDLL | None = None
_tried = False


def _cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "adfkit"


def _library_path() -> Path:
    """Where the library built from this SOURCE for this PyBullet lives (its hash in the name)."""
    h = hashlib.sha256(SOURCE.read_bytes() + pb.__file__.encode()).hexdigest()[:12]
    return _cache_dir() / f"state_calls-{h}.so"


def _build(path: Path) -> bool:
    cc = shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc")
    if cc is None:
        return False
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(suffix=".so", dir=path.parent)
    os.close(fd)
    try:
        done = subprocess.run(
            [cc, "-O2", "-shared", "-fPIC", "-o", tmp, str(SOURCE), "-ldl", "-lm"], capture_output=True, timeout=120
        )
        if done.returncode != 0:
            return False
        os.replace(tmp, path)  # atomic: another process building the same file meanwhile is harmless
        return True
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def _load() -> ctypes.CDLL | None:
    """The built library with PyBullet's C API bound, or None (see the module)."""
    global _lib, _tried
    if _tried:
        return _lib
    _tried = True
    if os.environ.get("ADFKIT_NO_C"):
        return None
    path = _library_path()
    try:
        if not path.is_file() and not _build(path):
            return None
        lib = ctypes.CDLL(str(path))
    except (OSError, subprocess.SubprocessError):
        return None
    if lib.adfkit_bind(pb.__file__.encode()) != 0:
        return None
    vp, i, ptr = ctypes.c_void_p, ctypes.c_int, ctypes.c_void_p
    lib.adfkit_last_client.restype = vp
    lib.adfkit_read_bases.argtypes = (vp, i, ptr, ptr)
    lib.adfkit_read_bases.restype = i
    lib.adfkit_apply.argtypes = (vp, i, ptr, ptr, ptr, i, ptr, ptr, ptr, ptr)
    lib.adfkit_apply.restype = None
    d = ctypes.c_double
    lib.adfkit_springs_apply.argtypes = (vp, ptr, ptr, d, d, ptr, ptr)
    lib.adfkit_springs_apply.restype = i
    lib.path = str(path)
    _lib = lib
    return lib


class StateCalls:
    """The C calls of one physics client (``for_client``)."""

    def __init__(self, lib: ctypes.CDLL, client: int) -> None:
        self.lib, self.client = lib, client

    def reader(self, uids: list[int]):
        """A callable that reads the base states of ``uids`` (in that order) and returns them as a new
        (n, 13) array: position, quaternion (x, y, z, w), linear and angular velocity."""
        ids = np.ascontiguousarray(uids, dtype=np.intc)
        n = len(ids)
        out = np.empty((n, 13))
        read, client, at_ids, at_out = self.lib.adfkit_read_bases, self.client, ids.ctypes.data, out.ctypes.data

        def read_bases() -> np.ndarray:
            failed = read(client, n, at_ids, at_out)
            if failed:
                raise RuntimeError(f"PyBullet could not read the state of body {int(ids[-failed - 1])}")
            return out.copy()

        read_bases.ids = ids  # keep the arrays the pointers point into
        read_bases.out = out
        return read_bases

    def applier(self, uids: list[int], links: list[int], fuids: list[int], flinks: list[int]):
        """A callable ``apply(torques, forces, at)`` (C-contiguous float arrays, (n, 3), (m, 3), (m, 3);
        forces None: torques alone): each body's torque in the world frame, then each pushed body's
        force at ``at``, one PyBullet command each, in that order (applyExternalTorque, then
        applyExternalForce, as the Python calls make them)."""
        keep = [np.ascontiguousarray(a, dtype=np.intc) for a in (uids, links, fuids, flinks)]
        n, m = len(keep[0]), len(keep[2])
        call, client = self.lib.adfkit_apply, self.client
        u, lk, fu, fl = (a.ctypes.data for a in keep)

        def apply(torques: np.ndarray, forces: np.ndarray | None, at: np.ndarray | None) -> None:
            if forces is None:
                call(client, n, u, lk, torques.ctypes.data, 0, None, None, None, None)
            else:
                call(client, n, u, lk, torques.ctypes.data, m, fu, fl, forces.ctypes.data, at.ctypes.data)

        apply.keep = keep
        return apply


def for_client(cid: int) -> StateCalls | None:
    """The C calls for PyBullet client ``cid`` (its plugin loaded into its server), or None where
    they cannot be had (see the module)."""
    if pb.getConnectionInfo(cid).get("connectionMethod") != pb.DIRECT:
        return None  # a GUI or shared-memory server steps in a thread of its own: its client's calls alone
    lib = _load()
    if lib is None:
        return None
    if pb.loadPlugin(lib.path, "_adfkit", physicsClientId=cid) < 0:
        return None
    client = lib.adfkit_last_client()
    return StateCalls(lib, client) if client else None
