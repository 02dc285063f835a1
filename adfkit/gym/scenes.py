"""Which suturing scene the environments play, and the world they build from it.

The project's own scene (sample_scenes/suturing/, written by `adfkit build-scene suturing`) is
the default; on a checkout without it, the public corpus's suturing set (launch indices 6-11)
when ../shared/corpus is present. Anything else is named by the caller (``scene=`` and
``indices=``).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
BUNDLED = ROOT / "sample_scenes" / "suturing" / "launch.yaml"
CORPUS_INDICES = "6-11"

#: distance from a PSM's RCM to the needle the setup joints leave when they must move the arm
#: (mid-range of the LND's 0-0.24 m insertion)
SETUP_DISTANCE = 0.17


#: the world methods the environments use beyond stepping and reading bodies
NEEDS = (
    "save_state",
    "restore_state",
    "place_body",
    "move_base",
    "set_collision",
    "nearest_point",
    "grasped",
    "actuate",
    "release",
    "ghost_pose",
    "overlapping",
)


class SceneUnavailable(FileNotFoundError):
    """No suturing scene to play: neither the bundled one nor the corpus."""


def corpus_launch() -> Path:
    base = Path(os.environ.get("ADFKIT_CORPUS", ROOT.parent / "shared" / "corpus"))
    return base / "src" / "launch.yaml"


def default_scene() -> tuple[Path, str | None]:
    """(launch file, launch indices) of the scene the environments play by default."""
    if BUNDLED.is_file():
        return BUNDLED, None
    corpus = corpus_launch()
    if corpus.is_file():
        return corpus, CORPUS_INDICES
    raise SceneUnavailable(
        f"no suturing scene: neither {BUNDLED} (write it with `adfkit build-scene suturing "
        f"{BUNDLED.parent}`) nor the corpus launch file {corpus} exists; pass scene=PATH"
    )


@dataclass
class Built:
    world: object
    psms: dict  # name -> adfkit.runner.PSM
    needle: object  # SimBody
    carried: list  # bodies moved with the needle when it is placed (its thread)
    grasp_in_needle: np.ndarray  # 4x4: where a PSM holds the needle, in the needle body frame
    setup_moves: dict  # name -> metres the setup joints moved the PSM base


def load(scene: str | Path | None, indices: str | None = None):
    """The scene model (adfkit.model.Scene) of the launch file ``scene`` (default: default_scene())."""
    from ..adf import load_scene, parse_indices
    from ..diagnostics import AdfError, Severity

    if scene is None:
        scene, default_indices = default_scene()
        indices = indices if indices is not None else default_indices
    diags: list = []
    model = load_scene(Path(scene), parse_indices(indices) if indices else None, diags)
    errors = [d for d in diags if d.severity >= Severity.ERROR]
    if errors:
        raise AdfError(errors)
    return model


def build(model, engine: str, arms, visuals: bool, setup_joints: bool = True) -> Built:
    """Build the scene model's world on ``engine`` and the PSMs; find the needle, its thread and
    the grasp point (the needle's surface nearest its centre of mass: mid-arc on a curved needle).
    The same model gives the same world, made in the same order, every time."""
    if engine not in ("pybullet", "mujoco"):
        raise ValueError(f"engine {engine!r}: choose 'pybullet' or 'mujoco'")
    world = _world(model, engine, visuals)
    from ..runner.psm import PSM

    psms = {name: PSM(world, name) for name in arms}
    others = [a.root.key for a in world.articulations]
    for name in ("psm1", "psm2"):
        if name not in psms and any(f"/{name}/" in k for k in others):
            psms[name] = PSM(world, name)
    needle = world.body("BODY Needle") if _unique(world, "BODY Needle") else world.body("Needle")
    carried = _attached(world, needle)
    com = np.array(needle.com_position())
    surface = world.nearest_point(needle, com)
    grasp = np.eye(4)
    grasp[:3, 3] = surface if surface is not None else com
    grasp_in_needle = np.linalg.inv(needle.world_matrix()) @ grasp
    moves = {}
    if setup_joints:
        for name in arms:
            moves[name] = _setup(world, psms[name], grasp[:3, 3])
    _soft_tissue(world, psms, needle)
    return Built(world, psms, needle, carried, grasp_in_needle, moves)


def _soft_tissue(world, psms, needle) -> None:
    """The jaws reach a needle lying on the phantom by pressing into the tissue (soft in the
    real scene; a hull here) rather than being pushed off their set-point: the arms do not
    collide with the static bodies of the needle's model (as adfkit.tasks.suture does)."""
    for sb in world.bodies:
        if sb.static and sb.model is needle.model:
            for psm in psms.values():
                for link in world.bodies:
                    if link.articulation is psm.art:
                        world.set_collision(sb, link, False)


def _world(model, engine: str, visuals: bool):
    from ..runner import Options

    if engine == "mujoco":
        from ..runner.mujoco.world import MujocoWorld

        missing = [m for m in NEEDS if not hasattr(MujocoWorld, m)]
        if missing:
            raise NotImplementedError(
                "engine='mujoco': the MuJoCo back end lacks what the environments use: "
                + ", ".join(missing)
                + "; use engine='pybullet'"
            )
        return MujocoWorld(model, Options(visuals=visuals))
    from ..runner import open_world

    # image observations: a frame every step, so the fastest renderer that works (cameras.choose_renderer)
    return open_world(model, Options(visuals=visuals, renderer="auto" if visuals else "tiny"))


def _unique(world, text: str) -> bool:
    key, _ = world.registry.find(text)
    return key is not None


def _attached(world, needle) -> list:
    """Bodies joined to the needle through chains of spring joints and constraints (its thread),
    which must move with it when it is placed."""
    links = {}
    for sj in world.springs.joints:
        links.setdefault(id(sj.parent), []).append(sj.child)
        links.setdefault(id(sj.child), []).append(sj.parent)
    for _, _, parent, child, *_ in world.constraints:
        links.setdefault(id(parent), []).append(child)
        links.setdefault(id(child), []).append(parent)
    seen, todo, out = {id(needle)}, [needle], []
    while todo:
        b = todo.pop()
        for n in links.get(id(b), []):
            if id(n) not in seen and not n.static and n.articulation is None:
                seen.add(id(n))
                out.append(n)
                todo.append(n)
    return out


def _setup(world, psm, target: np.ndarray) -> float:
    """Stand-in for the dVRK's setup joints (the challenge's scripts set them too): when
    ``target`` lies beyond the arm's reach, slide the PSM's base along the line from its RCM
    to the target until the target is SETUP_DISTANCE away. Returns how far it moved, m."""
    rcm = psm.base_in_world()[:3, 3]
    d = target - rcm
    dist = float(np.linalg.norm(d))
    reach = float(psm.kin.upper_limits[2]) - 0.02
    if dist <= reach:
        return 0.0
    shift = d / dist * (dist - SETUP_DISTANCE)
    pose = psm.base.world_matrix()
    pose[:3, 3] += shift
    world.move_base(psm.base, pose)
    return float(np.linalg.norm(shift))
