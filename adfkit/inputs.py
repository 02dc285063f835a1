"""The one door every file adfkit reads goes through (design.md, "Inputs at one door").

Policy, the same for every command:

- **Path text**: no NUL byte, no name component over 255 bytes, at most 4096 bytes in all
  (what Linux accepts); checked before the file system is asked anything.
- **Regular files only**: directories, devices (``/dev/zero``, ``/dev/stdin``), FIFOs and
  sockets are refused from ``stat`` alone, before anything is opened, so nothing blocks or
  streams forever. The file is then opened non-blocking and checked again on the descriptor.
- **Size cap** per kind of file (:data:`MAX_BYTES`); reads stop at the cap.
- **Encoding**: text is UTF-8 (a BOM is allowed); a bad byte is a located error.
- **The scene's tree**: a file named on the command line is read wherever it is (it must
  still be a regular file). Every file *it* names (world, environment, models, input devices,
  meshes, MJCF includes) must resolve, symlinks followed, inside the scene's tree: the named
  file's folder widened by :data:`TREE_LEVELS` parent folders (ADF projects reach their
  meshes through ``../../../meshes``), never above the second level of the file system
  (``/home/user``, ``/tmp/x``), or the folder in ``ADFKIT_INPUT_ROOT`` when that is set.

Every refusal is an :class:`AdfError` whose diagnostic is located at the key that named the
file (``referrer``) or, for a file named on the command line, at that file; its message
names the path (control characters escaped) and never quotes the file's content.
"""

from __future__ import annotations

import os
import stat
from dataclasses import dataclass
from pathlib import Path

from .diagnostics import AdfError, SourceLocation, error

#: Largest file read per kind, in bytes.
MAX_BYTES = {
    "adf": 16 * 1024 * 1024,  # the largest public ADF file is ~300 KB
    "xml": 64 * 1024 * 1024,  # URDF / MJCF
    "mesh": 512 * 1024 * 1024,  # STL / OBJ / PLY / DAE ...
    "text": 16 * 1024 * 1024,  # MTL and other small side files
    "image": 256 * 1024 * 1024,  # a volume slice or a texture
}
MAX_PATH_BYTES = 4096
MAX_NAME_BYTES = 255
#: Parent folders above the named file's folder that still belong to its scene.
TREE_LEVELS = 3
ROOT_ENV = "ADFKIT_INPUT_ROOT"

_HINT_TREE = (
    "files an ADF names must lie in the scene's folder tree; name the file on the command line "
    f"to read it anyway, or set {ROOT_ENV} to a wider folder"
)


def shown(path: str | os.PathLike | bytes, limit: int = 240) -> str:
    """A path as it may appear in a diagnostic: one line, control characters escaped, bounded."""
    if isinstance(path, bytes):
        text = path.decode("utf-8", "backslashreplace")
    else:
        text = os.fspath(path)
        if isinstance(text, bytes):  # pragma: no cover - fspath of a bytes path-like
            text = text.decode("utf-8", "backslashreplace")
    if text.isprintable() and len(text) <= limit:  # the common case, checked in C
        return text
    out = []
    for ch in text:
        code = ord(ch)
        if code < 32 or code == 127 or 0xD800 <= code <= 0xDFFF or ch in "\u2028\u2029\x85":
            out.append(f"\\x{code & 0xFF:02x}" if code < 256 or 0xD800 <= code <= 0xDFFF else f"\\u{code:04x}")
        else:
            out.append(ch)
    text = "".join(out)
    if len(text) > limit:
        text = text[: limit // 2] + "..." + text[-(limit // 2) :]
    return text


@dataclass(frozen=True)
class Tree:
    """The folder a scene's files must resolve into (symlinks followed)."""

    root: Path

    def contains(self, path: str | os.PathLike) -> bool:
        try:
            real = os.path.realpath(path)
        except (OSError, ValueError):
            return False
        root = str(self.root)
        return real == root or real.startswith(root.rstrip(os.sep) + os.sep)


def tree_of(named: str | os.PathLike) -> Tree:
    """The scene tree of a file named on the command line (see the module docstring)."""
    override = os.environ.get(ROOT_ENV)
    if override:
        return Tree(Path(os.path.realpath(override)))
    folder = Path(os.path.realpath(os.path.dirname(os.path.abspath(os.fspath(named))) or "."))
    parts = folder.parts
    keep = max(len(parts) - TREE_LEVELS, min(len(parts), 3))  # parts[0] is "/": keep /a/b at least
    return Tree(Path(*parts[:keep]))


def is_regular(path: str | os.PathLike) -> bool:
    """True for an existing regular file (symlinks followed); never raises, whatever the path."""
    try:
        return stat.S_ISREG(os.stat(path).st_mode)
    except (OSError, ValueError, TypeError):
        return False


def _fail(rule: str, message: str, path, referrer: SourceLocation | None, hint: str | None) -> AdfError:
    return AdfError(error(rule, message, referrer or SourceLocation(shown(path)), hint))


def check_path_text(path: str | os.PathLike, referrer: SourceLocation | None = None) -> None:
    """Refuse a path Linux cannot even look up (NUL byte, over-long name or path)."""
    try:
        raw = os.fsencode(path)
    except (TypeError, ValueError, UnicodeError):
        raise _fail(
            "bad-path",
            f"the path {shown(str(path))} cannot be encoded for the file system",
            str(path),
            referrer,
            "use a plain UTF-8 file name",
        ) from None
    if b"\0" in raw:
        raise _fail(
            "bad-path",
            f"the path {shown(raw)} holds a NUL byte",
            raw,
            referrer,
            "a file name cannot contain a NUL byte; fix the path",
        )
    if len(raw) > MAX_PATH_BYTES:
        raise _fail(
            "bad-path",
            f"the path is {len(raw)} bytes long (the limit is {MAX_PATH_BYTES})",
            raw,
            referrer,
            "shorten the path",
        )
    longest = max((len(part) for part in raw.split(b"/")), default=0)
    if longest > MAX_NAME_BYTES:
        raise _fail(
            "bad-path",
            f"a name in the path {shown(raw)} is {longest} bytes long (the limit is {MAX_NAME_BYTES})",
            raw,
            referrer,
            "shorten the file or folder name",
        )


def check_file(
    path: str | os.PathLike,
    kind: str = "adf",
    *,
    tree: Tree | None = None,
    referrer: SourceLocation | None = None,
    what: str = "file",
) -> Path:
    """Check ``path`` against the policy without opening it; returns it as a Path.

    ``tree`` None means the user named the file (no tree check); ``referrer`` locates the
    diagnostic at the key that named the file."""
    check_path_text(path, referrer)
    p = Path(path)
    try:
        st = os.stat(p)
    except FileNotFoundError:
        raise _fail(
            "file-not-found",
            f"no such {what}: {shown(p)}",
            p,
            referrer,
            "check the path; relative paths resolve against the naming file's folder "
            "(the current folder on the command line)",
        ) from None
    except NotADirectoryError:
        raise _fail(
            "file-not-found",
            f"no such {what}: {shown(p)} (a folder in the path is a file)",
            p,
            referrer,
            "check the path",
        ) from None
    except PermissionError:
        raise _fail(
            "file-unreadable", f"cannot read {shown(p)}: permission denied", p, referrer, "check the file's permissions"
        ) from None
    except OSError as exc:
        raise _fail(
            "file-unreadable",
            f"cannot read {shown(p)}: {exc.strerror or type(exc).__name__}",
            p,
            referrer,
            "check the path",
        ) from None
    if not stat.S_ISREG(st.st_mode):
        kind_word = (
            "a folder"
            if stat.S_ISDIR(st.st_mode)
            else "a FIFO"
            if stat.S_ISFIFO(st.st_mode)
            else "a device"
            if stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode)
            else "a socket"
            if stat.S_ISSOCK(st.st_mode)
            else "not a regular file"
        )
        raise _fail(
            "not-a-regular-file",
            f"{shown(p)} is {kind_word}, not a regular file",
            p,
            referrer,
            f"name a regular {what}; adfkit never reads devices, FIFOs or folders as files",
        )
    if tree is not None and not tree.contains(p):
        raise _fail(
            "outside-tree",
            f"{shown(p)} lies outside the scene's folder tree ({shown(tree.root)}); not read",
            p,
            referrer,
            _HINT_TREE,
        )
    cap = MAX_BYTES.get(kind, MAX_BYTES["adf"])
    if st.st_size > cap:
        raise _fail(
            "file-too-large",
            f"{shown(p)} is {st.st_size:,} bytes; the limit for a {kind} file is {cap:,}",
            p,
            referrer,
            "split the file, or check that this is the file you meant",
        )
    return p


def check_mesh(path: str | os.PathLike, *, tree: Tree | None = None, referrer: SourceLocation | None = None) -> Path:
    """:func:`check_file` for a mesh file, with ``mesh-not-found`` (located at the mesh's path,
    with a hint when only the letter case differs) for a mesh that is not there."""
    check_path_text(path, referrer)
    p = Path(path)
    if not os.path.lexists(p):
        hint = "check the path (ADF resolves mesh paths as in adf-format.md §6.2)"
        if p.parent.is_dir():
            stem = p.name.lower()
            near = [q.name for q in p.parent.iterdir() if q.name.lower() == stem]
            if near:
                hint = f"file names are case-sensitive: did you mean '{near[0]}'?"
        raise AdfError(error("mesh-not-found", f"mesh file not found: {shown(p)}", SourceLocation(shown(p)), hint))
    # a regular file under the mesh size cap, inside ``tree`` when another file named it
    return check_file(p, "mesh", tree=tree, referrer=referrer, what="mesh file")


def read_bytes(
    path: str | os.PathLike,
    kind: str = "adf",
    *,
    tree: Tree | None = None,
    referrer: SourceLocation | None = None,
    what: str = "file",
) -> bytes:
    """The file's bytes, after :func:`check_file`; reads at most the kind's cap."""
    p = check_file(path, kind, tree=tree, referrer=referrer, what=what)
    cap = MAX_BYTES.get(kind, MAX_BYTES["adf"])
    try:
        fd = os.open(p, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        raise _fail(
            "file-unreadable",
            f"cannot read {shown(p)}: {exc.strerror or type(exc).__name__}",
            p,
            referrer,
            "check the path and permissions",
        ) from None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):  # swapped between stat and open
            raise _fail(
                "not-a-regular-file", f"{shown(p)} is not a regular file", p, referrer, f"name a regular {what}"
            )
        chunks, total = [], 0
        while True:
            chunk = os.read(fd, min(1 << 20, cap + 1 - total))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
            if total > cap:
                raise _fail(
                    "file-too-large",
                    f"{shown(p)} holds more than {cap:,} bytes",
                    p,
                    referrer,
                    "split the file, or check that this is the file you meant",
                )
        return b"".join(chunks)
    except OSError as exc:
        raise _fail(
            "file-unreadable",
            f"cannot read {shown(p)}: {exc.strerror or type(exc).__name__}",
            p,
            referrer,
            "check the file",
        ) from None
    finally:
        os.close(fd)


def decode_utf8(data: bytes, path: str | os.PathLike) -> str:
    """UTF-8 text (BOM allowed); a bad byte is an error located at its line and column."""
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        before = data[: exc.start]
        line = before.count(b"\n") + 1
        col = exc.start - (before.rfind(b"\n") + 1) + 1
        raise AdfError(
            error(
                "yaml-encoding",
                f"invalid UTF-8 byte 0x{data[exc.start]:02x}",
                SourceLocation(shown(path), line, col),
                "save the file as UTF-8",
            )
        ) from None


def read_text(
    path: str | os.PathLike,
    kind: str = "adf",
    *,
    tree: Tree | None = None,
    referrer: SourceLocation | None = None,
    what: str = "file",
) -> str:
    """The file as UTF-8 text, after :func:`read_bytes`."""
    return decode_utf8(read_bytes(path, kind, tree=tree, referrer=referrer, what=what), path)


__all__ = [
    "MAX_BYTES",
    "ROOT_ENV",
    "TREE_LEVELS",
    "Tree",
    "check_file",
    "check_path_text",
    "decode_utf8",
    "is_regular",
    "read_bytes",
    "read_text",
    "shown",
    "tree_of",
]


def scene_file(path: str | os.PathLike) -> Path:
    """The ADF file a command plays or summarises when the user names ``path``: the path itself,
    or a folder's ``launch.yaml`` (as AMBF's launcher reads a folder). A folder without one is a
    located ``not-a-regular-file`` error that names the YAML files it holds."""
    p = Path(path)
    check_path_text(p)
    if not p.is_dir():
        return p
    launch = p / "launch.yaml"
    if launch.is_file():
        return launch
    try:
        yamls = sorted(x.name for x in p.iterdir() if x.suffix.lower() in (".yaml", ".yml") and x.is_file())
    except OSError:
        yamls = []
    listed = ", ".join(yamls[:8]) + (" ..." if len(yamls) > 8 else "")
    raise _fail(
        "not-a-regular-file",
        f"{shown(p)} is a folder without a launch.yaml",
        p,
        None,
        f"name the ADF file to use: one of {listed}" if yamls else "name an ADF file (launch, world or model)",
    )
