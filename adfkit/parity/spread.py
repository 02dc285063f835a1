"""AMBF's own spread: how far AMBF stands from itself when a scene's dynamic roots (its dynamic
bodies no dynamic body holds by a joint) start a distance nobody could measure from where the
files put them. A scene that amplifies such a nudge (a thread
lying on a phantom, twisting as it creeps) gives a different answer each time its start is
perturbed; a gap to adfkit no larger than that spread says nothing about adfkit
(docs/parity.md, "Within a millimetre, not a degree").

The nudge is made in a copy of the scene's files: each moved body's `location` `position` is
rewritten in place, at the very characters of its numbers, the rest of every file as it is. The
copy holds the scene's ADF files (its launch, world and model files) as real files in real
folders and everything else (meshes, textures) as links to the originals, so the paths inside the
files lead where they led. The copy is read back and checked: the moved bodies stand exactly the
nudge away and no other body moved."""

from __future__ import annotations

import os
import shutil
from dataclasses import dataclass, field
from pathlib import Path

import yaml

#: the nudges, one AMBF run each: every dynamic root moved along +x, -x, +y, -y, +z, then -z. One
#: nudge is one draw of a chaotic answer: the bundled scene at rest, its needle moved 0.1 µm, turns
#: a thread element 76° from AMBF's unnudged run under +x, 7° along the diagonal, 93° under -z; and
#: a body moved along one axis keeps a symmetry the scene may have (the falling thread lies in the
#: plane x = 0 and AMBF's stays in it under a nudge along y or z, while one along x blows its world
#: up; bench/ambf_nudged.py)
DIRECTIONS = {
    "+x": (1.0, 0.0, 0.0),
    "-x": (-1.0, 0.0, 0.0),
    "+y": (0.0, 1.0, 0.0),
    "-y": (0.0, -1.0, 0.0),
    "+z": (0.0, 0.0, 1.0),
    "-z": (0.0, 0.0, -1.0),
}


#: the longest nudge --spread takes, whatever the tolerance: a millimetre (the default position
#: tolerance) is a move anyone could measure, not a start nobody could
LONGEST_NUDGE_M = 1e-3
#: the hint beside a nudge no_nudge refuses
NUDGE_HINT = "a start nobody could measure: leave --spread-by out (1e-7 m)"


def no_nudge(by_m: float, tolerance_m: float) -> str | None:
    """Why a nudge of ``by_m`` metres is not one --spread can take (None: it is): the nudged
    bodies start that far from where AMBF's unnudged run starts them, so its spread is at least the
    nudge and would excuse gaps the nudge itself made (a box moved 1 m spreads 1008 mm and 77°,
    moved 1 m down into the slab it rests on). A nudge must stay below the position tolerance and
    below a millimetre; it must be a positive number at all."""
    if not 0 < by_m < float("inf"):
        return "--spread-by takes a positive distance in metres"
    limit = min(tolerance_m, LONGEST_NUDGE_M) if tolerance_m > 0 else LONGEST_NUDGE_M
    if by_m < limit:
        return None
    below = "--tolerance-mm" if limit == tolerance_m else "a millimetre"
    return (
        f"--spread-by {by_m:g} m is not below {below} ({limit * 1e3:g} mm): the nudged bodies would start "
        "that far from AMBF's own start, and AMBF's spread would excuse gaps the nudge itself made"
    )


@dataclass
class Nudge:
    """Which bodies a nudged copy moved, and which it could not."""

    by_m: float
    directions: list[str] = field(default_factory=lambda: list(DIRECTIONS))
    moved: list[str] = field(default_factory=list)  # ADF body names ("Needle")
    not_moved: list[dict] = field(default_factory=list)  # {"name", "why"}


def within(gap_m: float, gap_deg: float, spread_m: float, spread_deg: float, tol_m: float, tol_deg: float) -> bool:
    """The verdict for a body past the tolerances: its gap to adfkit is within AMBF's own spread
    when neither its position nor its angle gap passes AMBF's spread by more than the tolerance
    (a gap the tolerance away from AMBF's own answer to a nudged start is one AMBF could give)."""
    return gap_m <= spread_m + tol_m and gap_deg <= spread_deg + tol_deg


def dynamic_roots(scene) -> list[tuple[Path, str]]:
    """(model file, ADF body name) of every dynamic body (a positive mass) no dynamic body holds
    by a joint: a body on its own, the first body of a tree, or one hanging from a static body (a
    thread from its fixed anchor, an arm's first link from its base). Moved alone, each starts
    that much apart from what holds it and what it holds: the tree's joints start stretched by the
    nudge (a tree moved whole, its joints as they were, kicks AMBF's bundled thread a quarter as
    far: 22° where its needle alone moved gives 93°)."""
    out = []
    for m in scene.all_models():
        dynamic = {b.identifier for b in m.bodies if (b.mass or 0.0) > 0.0}
        held = {j.child for j in m.joints if j.parent in dynamic}
        for b in m.bodies:
            if b.identifier in dynamic and b.identifier not in held and m.path:
                out.append((Path(m.path).resolve(), b.identifier.removeprefix("BODY ")))
    return out


def _scene_files(scene, path: Path) -> list[Path]:
    files = [path.resolve()]
    if scene.world is not None and scene.world.path:
        files.append(Path(scene.world.path).resolve())
    files += [Path(m.path).resolve() for m in scene.all_models() if m.path]
    return list(dict.fromkeys(files))


def _referenced(scene) -> list[Path]:
    """The folders a scene's model files take meshes from and the launch file's other files."""
    out = []
    la = scene.launch
    if la is not None and la.path:
        for rel in (la.color_config, la.input_devices_config):
            if rel:
                out.append((Path(la.path).parent / rel).resolve())
    for m in scene.all_models():
        for rel in (m.high_resolution_path, m.low_resolution_path):
            if m.path and rel:
                out.append((Path(m.path).parent / rel).resolve())
    return out


def _shadow(files: list[Path], others: list[Path], out: Path) -> tuple[Path, Path]:
    """A copy of the common folder of ``files`` and ``others`` in ``out``: ``files`` copied, the
    folders holding them made, every other entry of those folders a link to the original. The
    common folder and its copy."""
    root = Path(os.path.commonpath([str(p if p in others else p.parent) for p in files + others]))
    dst = out / (root.name or "root")
    made = {dst}
    for f in files:
        rel = f.relative_to(root)
        d = dst
        for part in rel.parts[:-1]:
            d = d / part
            made.add(d)
        d.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(f, dst / rel)
    for d in sorted(made):
        src = root / d.relative_to(dst)
        for entry in src.iterdir():
            if not (d / entry.name).exists() and not (d / entry.name).is_symlink():
                (d / entry.name).symlink_to(entry)
    return root, dst


def _position_nodes(root: yaml.Node, body: str) -> dict[str, yaml.ScalarNode]:
    """The scalar nodes of BODY ``body``'s location position, by axis."""
    from ..adf.yamlnodes import mapping_items

    def child(node, key):
        if isinstance(node, yaml.MappingNode):
            for k, _, v in mapping_items(node):
                if k == key:
                    return v
        return None

    pos = child(child(child(root, f"BODY {body}"), "location"), "position")
    return {a: n for a in "xyz" if isinstance(n := child(pos, a), yaml.ScalarNode) and not n.style}


def _uses(root: yaml.Node) -> dict[int, int]:
    """How many times each node of a composed document is reached: more than once for a node
    written once with an anchor (``&p``) and used again by an alias (``*p``)."""
    out: dict[int, int] = {}
    stack, on_path = [root], set()
    while stack:
        n = stack.pop()
        if n is None:  # leaving a node
            on_path.discard(stack.pop())
            continue
        out[id(n)] = out.get(id(n), 0) + 1
        if isinstance(n, yaml.MappingNode | yaml.SequenceNode) and id(n) not in on_path:
            on_path.add(id(n))
            stack += [id(n), None]
            kids = [x for kv in n.value for x in kv] if isinstance(n, yaml.MappingNode) else list(n.value)
            stack += reversed(kids)
    return out


def _moved_text(text: str, file: str, moves: dict[str, tuple[float, float, float]]) -> tuple[str, dict[str, str]]:
    """``text`` with each body of ``moves`` (ADF name -> metres along x, y, z) moved; why a body
    could not be, by name."""
    from ..adf.yamlnodes import compose

    starts = [0]
    for line in text.splitlines(keepends=True):
        starts.append(starts[-1] + len(line))
    root = compose(text, file)
    uses = _uses(root)
    edits, why = [], {}
    for body, d in moves.items():
        nodes = _position_nodes(root, body)
        axes = [a for a, v in zip("xyz", d) if v != 0.0]
        if any(a not in nodes for a in axes):
            why[body] = "its file gives no plain number for its location's position " + "/".join(axes)
            continue
        if any(uses.get(id(nodes[a]), 0) > 1 for a in axes):  # an anchor: rewritten, every alias would move
            why[body] = "its location's position is a YAML anchor the file uses elsewhere (an alias, *name)"
            continue
        for a, v in zip("xyz", d):
            if v == 0.0:
                continue
            n = nodes[a]
            s, e = (starts[m.line] + m.column for m in (n.start_mark, n.end_mark))
            if text[s:e] != n.value:
                why[body] = "its position could not be found in the file's text"
                break
            edits.append((s, e, repr(float(n.value) + v)))
    for s, e, new in sorted(edits, reverse=True):
        text = text[:s] + new + text[e:]
    return text, why


def nudged_copy(
    path: Path, indices: list[int] | None, moves: dict[tuple[Path, str], tuple[float, float, float]], out: Path
) -> tuple[Path, dict[str, str]]:
    """A copy in ``out`` of the scene ``path`` loads with ``indices`` (a launch, world or model
    file), where each body of ``moves`` ((its model file, its ADF name) -> metres along x, y, z)
    stands that much further along its location's position. The copy's scene file and why a body
    was not moved, by name. ValueError when the copy, read back, does not hold exactly those
    moves (a body two files place under one name in one file, a file adfkit cannot rewrite)."""
    from ..adf import load_scene

    scene = load_scene(path, indices, [])
    files = _scene_files(scene, path)
    root, dst = _shadow(files, _referenced(scene), out)
    why: dict[str, str] = {}
    for f in sorted({f for f, _ in moves}):
        mine = {b: d for (g, b), d in moves.items() if g == f}
        text, not_moved = _moved_text(f.read_text(encoding="utf-8"), str(f), mine)
        why.update(not_moved)
        (dst / f.relative_to(root)).write_text(text, encoding="utf-8")
    copy = dst / path.resolve().relative_to(root)
    _check(scene, load_scene(copy, indices, []), {(f, b): d for (f, b), d in moves.items() if b not in why}, root, dst)
    return copy, why


def _check(before, after, moves, root: Path, dst: Path) -> None:
    """ValueError unless ``after``'s bodies stand where ``before``'s do, ``moves`` added."""

    def places(scene, base: Path):
        out = {}
        for m in scene.all_models():
            f = Path(m.path).resolve() if m.path else None
            rel = f.relative_to(base) if f is not None and f.is_relative_to(base) else f
            for b in m.bodies:
                p = b.location.position if b.location is not None else None
                out.setdefault((rel, b.identifier.removeprefix("BODY ")), []).append(
                    (p.x, p.y, p.z) if p is not None else (0.0, 0.0, 0.0)
                )
        return out

    # the copy read back through its links: its files resolve to the copy's real files
    a, b = places(before, root), places(after, dst.resolve())
    if a.keys() != b.keys():
        raise ValueError("the nudged copy does not load the scene's bodies")
    for key, where in a.items():
        d = moves.get((root / key[0] if key[0] is not None else None, key[1]), (0.0, 0.0, 0.0))
        for p, q in zip(where, b[key], strict=True):
            if any(abs(pi + di - qi) > 1e-12 * max(1.0, abs(pi)) for pi, di, qi in zip(p, d, q)):
                raise ValueError(f"the nudged copy moves BODY {key[1]} otherwise than asked")


def nudge_dynamic_roots(
    path: Path, indices: list[int] | None, by: float, direction: str, out: Path
) -> tuple[Path, Nudge]:
    """A copy of the scene (in ``out``) with every dynamic root (dynamic_roots) moved ``by`` metres along
    ``direction`` (a key of DIRECTIONS); the copy's scene file and what was moved."""
    from ..adf import load_scene

    bodies = dynamic_roots(load_scene(path, indices, []))
    d = tuple(by * c for c in DIRECTIONS[direction])
    copy, why = nudged_copy(path, indices, {fb: d for fb in bodies}, out)
    nudge = Nudge(by, moved=[b for _, b in bodies if b not in why])
    nudge.not_moved = [{"name": b, "why": w} for b, w in why.items()]
    return copy, nudge
