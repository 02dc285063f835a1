"""The margin Bullet's broadphase grows a moving body's box by (``gDbvtMargin``), one per process.

btDbvtBroadphase keeps each body's box in its tree grown by this margin; while a body's box stays
inside the grown one, a step does not touch the tree, and only a box that leaves it is put back
and tested against both trees (every other body's box) for new pairs. Bullet's default is 0.05 m,
which AMBF keeps; PyBullet sets 0 at every world it makes (createEmptyDynamicsWorld), so every body
that moved at all, by a nanometre, tests its box against every other body's at every physics step:
on the corpus suturing set a tenth of the run's CPU under ``adfkit run``'s settings, a fifth under
``Options()``'s, the PSMs'
creeping links and the resting thread's 40 bodies each doing it every 1 ms step. AMBF's 0.05 m here
costs more than it saves (the thread's bodies, millimetres apart, each come to overlap every other's
grown box: more pairs for the narrowphase every step); a margin of MARGIN a body creeping by
micrometres a step keeps for hundreds of steps, and adds few pairs.

The variable is not exported: its place is read from the symbol table of PyBullet's module file
(ELF, as the PyPI wheels ship it, symbols kept) and found in memory from an exported symbol's
(PyInit_pybullet). Where that cannot be done, or the value there is not one PyBullet or Bullet
puts (0 or 0.05), nothing is written and every world plays with PyBullet's 0.
"""

from __future__ import annotations

import ctypes
import struct

import pybullet as pb

#: m: the margin every PyBullet world of adfkit's plays with: see the module
MARGIN = 5e-4
#: m: PyBullet's own, where MARGIN cannot be put in force
PYBULLET = 0.0

_cell: ctypes.c_double | None = None
_looked = False


def _symbols(path: str, names: set[str]) -> dict[str, tuple[int, int]]:
    """{name: (value, size)} of ``names`` in the ELF64 little-endian file's symbol tables."""
    out: dict[str, tuple[int, int]] = {}
    with open(path, "rb") as f:
        head = f.read(64)
        if head[:4] != b"\x7fELF" or head[4] != 2 or head[5] != 1:
            return out
        (shoff,) = struct.unpack_from("<Q", head, 0x28)
        shentsize, shnum = struct.unpack_from("<HH", head, 0x3A)
        f.seek(shoff)
        table = f.read(shentsize * shnum)
        secs = [struct.unpack_from("<IIQQQQIIQQ", table, i * shentsize) for i in range(shnum)]
        for sec in secs:
            if sec[1] not in (2, 11):  # SHT_SYMTAB, SHT_DYNSYM
                continue
            strtab = secs[sec[6]]
            f.seek(strtab[4])
            strings = f.read(strtab[5])
            f.seek(sec[4])
            syms = f.read(sec[5])
            for off in range(0, len(syms) - 23, 24):
                name_at, _info, _other, _shndx, value, size = struct.unpack_from("<IBBHQQ", syms, off)
                name = strings[name_at : strings.index(b"\0", name_at)].decode("ascii", "replace")
                if name in names:
                    out[name] = (value, size)
    return out


def _margin_cell() -> ctypes.c_double | None:
    """PyBullet's gDbvtMargin in memory, or None where it cannot be found safely (see the module)."""
    global _cell, _looked
    if not _looked:
        _looked = True
        try:
            syms = _symbols(pb.__file__, {"gDbvtMargin", "PyInit_pybullet"})
            if "gDbvtMargin" in syms and "PyInit_pybullet" in syms and syms["gDbvtMargin"][1] == 8:
                lib = ctypes.CDLL(pb.__file__)  # the loaded module (dlopen gives its handle again)
                base = ctypes.cast(lib.PyInit_pybullet, ctypes.c_void_p).value - syms["PyInit_pybullet"][0]
                cell = ctypes.c_double.from_address(base + syms["gDbvtMargin"][0])
                if cell.value in (0.0, 0.05):
                    _cell = cell
        except (OSError, ValueError, AttributeError, TypeError, struct.error):
            _cell = None
    return _cell


def use(margin: float) -> None:
    """Put ``margin`` in force for every PyBullet world of the process (where it can be: the module)."""
    cell = _cell if _looked else _margin_cell()
    if cell is not None and cell.value != margin:
        cell.value = margin


def margin_now() -> float | None:
    """The margin in force, or None where it cannot be read."""
    cell = _margin_cell()
    return None if cell is None else cell.value
