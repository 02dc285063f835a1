"""The house drawn from its own imports: no import circles, and the core never imports the edges."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _modules(pkg: str) -> dict[str, Path]:
    out = {}
    for f in (ROOT / pkg).rglob("*.py"):
        parts = f.relative_to(ROOT).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = f
    return out


def _edges(mods: dict[str, Path]) -> dict[str, set[str]]:
    """Every import (module level or inside a function) of one module of the house by another;
    importing a package's own parent package is not an edge (Python runs it first anyway)."""
    edges: dict[str, set[str]] = {m: set() for m in mods}
    for m, f in mods.items():
        is_pkg = f.name == "__init__.py"
        for node in ast.walk(ast.parse(f.read_text(encoding="utf-8"))):
            names: list[str] = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = m.split(".") if is_pkg else m.split(".")[:-1]
                if node.level:
                    base = base[: len(base) - (node.level - 1)]
                    mod = ".".join(base) + (f".{node.module}" if node.module else "")
                else:
                    mod = node.module or ""
                names = [mod] + [f"{mod}.{a.name}" for a in node.names]
            for t in names:
                if t in mods and t != m and not m.startswith(t + "."):
                    edges[m].add(t)
    return edges


def _cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (iterative Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    found = []
    for start in edges:
        if start in index:
            continue
        work = [(start, iter(sorted(edges[start])))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on.add(start)
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(edges[w]))))
                elif w in on:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    x = stack.pop()
                    on.discard(x)
                    comp.append(x)
                    if x == v:
                        break
                if len(comp) > 1:
                    found.append(sorted(comp))
    return found


def test_the_cycle_finder_finds_a_circle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []


@pytest.mark.parametrize("pkg", ["adfkit", "addon"])
def test_no_import_circles(pkg):
    assert _cycles(_edges(_modules(pkg))) == []


# the core (model, ADF I/O, validator) never reaches up into the edges
CORE = ("adfkit.model", "adfkit.adf", "adfkit.validator")
EDGES = (
    "adfkit.runner",
    "adfkit.tasks",
    "adfkit.gym",
    "adfkit.converters",
    "adfkit.commands",
    "adfkit.scenes",
    "adfkit.dataset",
)


def test_the_core_does_not_import_the_edges():
    edges = _edges(_modules("adfkit"))
    up = sorted(f"{m} -> {t}" for m, ts in edges.items() if m.startswith(CORE) for t in ts if t.startswith(EDGES))
    assert up == []


# the runner: an engine-neutral core and two back ends of the same layout, side by side
BACK_ENDS = ("adfkit.runner.pybullet", "adfkit.runner.mujoco")


def _in(m: str, pkg: str) -> bool:
    return m == pkg or m.startswith(pkg + ".")


def test_the_two_back_ends_do_not_import_each_other():
    edges = _edges(_modules("adfkit"))
    across = sorted(
        f"{m} -> {t}"
        for a in BACK_ENDS
        for b in BACK_ENDS
        if a != b
        for m, ts in edges.items()
        if _in(m, a)
        for t in ts
        if _in(t, b)
    )
    assert across == []


def test_the_runner_core_does_not_import_a_back_end():
    """Only ``runner.engines`` (which opens a world on either) and the package's lazy names know them."""
    edges = _edges(_modules("adfkit"))
    core = [m for m in edges if _in(m, "adfkit.runner") and not any(_in(m, b) for b in BACK_ENDS)]
    up = sorted(
        f"{m} -> {t}"
        for m in core
        if m not in ("adfkit.runner", "adfkit.runner.engines")
        for t in edges[m]
        if any(_in(t, b) for b in BACK_ENDS)
    )
    assert up == []


def test_the_back_ends_have_the_same_layout_and_small_files():
    runner = ROOT / "adfkit" / "runner"
    layout = {b: {f.name for f in (runner / b.rsplit(".", 1)[1]).glob("*.py")} for b in BACK_ENDS}
    shared = {"__init__.py", "world.py", "assemble.py", "interact.py", "stability.py"}
    for b, files in layout.items():
        assert shared <= files, f"{b} lacks {sorted(shared - files)}"
    long = sorted(
        f"{f.relative_to(ROOT)}: {n} lines"
        for f in runner.rglob("*.py")
        if (n := len(f.read_text(encoding="utf-8").splitlines())) > 400
    )
    assert long == []


@pytest.mark.parametrize(
    "module, name",
    [("adfkit.runner.pybullet.world", "PyBulletWorld"), ("adfkit.runner.mujoco.world", "MujocoWorld")],
)
def test_a_back_end_method_is_not_shadowed_by_the_core(module, name):
    """Each back end is its halves (Assembly, Interaction, ...) over the engine-neutral World:
    what a half defines must be what the world calls, not World's default. With World first
    among the bases, both engines' batched contacts_among (one query an arm, or one contact
    table a step) were never called: the default asked body by body."""
    import importlib

    from adfkit.runner.world import World

    pytest.importorskip(module.split(".")[2])
    cls = getattr(importlib.import_module(module), name)
    for half in cls.__mro__[1:]:
        if half in (World, object):
            continue
        for attr, value in vars(half).items():
            if callable(value) and not attr.startswith("__"):
                assert getattr(cls, attr) is value, (
                    f"{name}.{attr} is {getattr(cls, attr).__qualname__}, not {half.__name__}'s"
                )


def test_only_the_ros_front_end_imports_rospy():
    """ROS stays at the edge: rospy (and the messages generated for it) are imported under
    adfkit/ros only, and only the `adfkit ros` command imports that package."""
    import re

    pattern = re.compile(
        r"^\s*(import|from)\s+(rospy|rosgraph|genpy|ambf_msgs|std_msgs|sensor_msgs|geometry_msgs)\b", re.M
    )
    outside = sorted(
        str(f.relative_to(ROOT))
        for f in (ROOT / "adfkit").rglob("*.py")
        if "ros" not in f.relative_to(ROOT / "adfkit").parts[:1] and pattern.search(f.read_text(encoding="utf-8"))
    )
    assert outside == []
    edges = _edges(_modules("adfkit"))
    users = sorted({m for m, ts in edges.items() if not _in(m, "adfkit.ros") for t in ts if _in(t, "adfkit.ros")})
    assert users == ["adfkit.commands.ros"]
