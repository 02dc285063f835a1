"""What each body of a suturing scene is to the suture: the needle, the thread, a robot's link,
or tissue. One definition, read by the planner (the tools' clearance), the guarded motions and
the observer (the verdicts), so that what the plan keeps off is what the verdict judges.

- **The needle**: the body named Needle.
- **The thread**: the bodies joined to the needle, directly or through each other, by the
  scene's joints (a chain of elements), static bodies and robots' links left out; in the
  chain's order from the needle.
- **Robots**: the links of the PSMs the task drives (their articulations), and of any other
  arm a caller names.
- **Tissue**: every other body that has something to collide with, from whichever model file it
  comes: the phantom, its hole bodies (static, or on springs as in the challenge's phantom),
  a second phantom file, a tray. A body the scene does not want judged as tissue is named in
  ``not_tissue`` (``adfkit suture --not-tissue NAME``): a name or a key suffix, as
  ``World.body`` finds bodies.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..adf.paths import collision_mesh_path
from ..model.semantics import collision_primitives


def _short(ref: str | None) -> str:
    return (ref or "").split()[-1] if ref else ""


def collides(sb) -> bool:
    """Whether a body has a collision shape: primitives, or a mesh it collides as."""
    prims = collision_primitives(sb.body)
    if prims is not None:
        return bool(prims)
    return collision_mesh_path(sb.model, sb.body) is not None


def joined_chain(world, start) -> list:
    """The dynamic bodies joined to ``start`` through the scene's joints (either end), breadth
    first from it, ``start`` left out."""
    by_name: dict[tuple[int, str], object] = {}
    for sb in world.bodies:
        by_name[(id(sb.model), _short(sb.body.identifier))] = sb
    links: dict[int, list] = {}
    for m in {id(sb.model): sb.model for sb in world.bodies}.values():
        for j in getattr(m, "joints", None) or []:
            a, b = by_name.get((id(m), _short(j.parent))), by_name.get((id(m), _short(j.child)))
            if a is None or b is None:
                continue
            links.setdefault(id(a), []).append(b)
            links.setdefault(id(b), []).append(a)
    seen, order, todo = {id(start)}, [], [start]
    while todo:
        nxt = []
        for sb in todo:
            for o in links.get(id(sb), []):
                if id(o) in seen or o.static or o.articulation is not None:
                    continue
                seen.add(id(o))
                order.append(o)
                nxt.append(o)
        todo = nxt
    return order


def _named(sb, names) -> bool:
    for n in names:
        if n == sb.name or n == sb.body.identifier or sb.key.endswith(n):
            return True
    return False


@dataclass
class Roles:
    needle: object
    thread: list = field(default_factory=list)
    robots: dict[str, list] = field(default_factory=dict)  # arm name -> its links
    tissue: list = field(default_factory=list)
    not_tissue: list[str] = field(default_factory=list)  # what the scene said is not tissue

    def tissue_ids(self) -> set[int]:
        return {id(sb) for sb in self.tissue}


def body_roles(world, needle, psms: dict, not_tissue=()) -> Roles:
    """Every body of ``world`` sorted as the module docstring says; ``psms``: {name: PSM}."""
    robots = {n: [sb for sb in world.bodies if sb.articulation is psm.art] for n, psm in psms.items()}
    thread = joined_chain(world, needle)
    taken = {id(needle)} | {id(sb) for sb in thread} | {id(sb) for links in robots.values() for sb in links}
    tissue = [sb for sb in world.bodies if id(sb) not in taken and not _named(sb, not_tissue) and collides(sb)]
    return Roles(needle, thread, robots, tissue, list(not_tissue))


def task_roles(task) -> Roles:
    """The roles a task sorted (SutureTask.roles), or sorted now for a task that has none (a
    Gymnasium task's watch: its ``psms`` the robots)."""
    have = getattr(task, "roles", None)
    return have if have is not None else body_roles(task.world, task.needle, getattr(task, "psms", {}))
