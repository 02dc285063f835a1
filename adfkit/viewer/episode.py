"""A recorded ``adfkit suture`` output read for replay: its frames (from the dataset that
``--record`` writes: the needle's pose, each PSM's joints and jaw, the phase, the time) and the
per-pair verdicts of ``metrics.json``. A replay is kinematic: the world is put in each frame's
state, not simulated, so scrubbing back and forth is exact."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import inputs
from ..diagnostics import AdfError, SourceLocation, error


@dataclass
class Frame:
    step: int
    time_s: float
    phase: str
    needle: np.ndarray | None
    psms: dict  # {name: {"jp": [...], "jaw": rad, ...}}


@dataclass
class Episode:
    folder: Path
    frames: list[Frame]
    pairs: list[dict] = field(default_factory=list)  # metrics.json "pairs"
    metrics: dict = field(default_factory=dict)

    def verdicts_markdown(self) -> str:
        if not self.pairs:
            return "no per-pair verdicts in metrics.json"
        rows = ["| pair | verdict | why |", "|---|---|---|"]
        for p in self.pairs:
            ok = p.get("passed")
            why = p.get("reason") or p.get("failure") or ""
            rows.append(f"| {p.get('pair', p.get('index', '?'))} | {'passed' if ok else 'NOT passed'} | {why} |")
        return "\n".join(rows)


def _fail(message: str, where: Path, hint: str) -> AdfError:
    return AdfError(error("bad-episode", message, SourceLocation(str(where)), hint))


def load_episode(folder: str | Path) -> Episode:
    """The episode in ``folder`` (an ``adfkit suture --record`` output, or its ``dataset``
    folder). A folder without recorded frames is a located error that says how to make one."""
    root = Path(folder)
    if not root.is_dir():
        raise _fail(f"{inputs.shown(root)} is not a folder", root, "give the --out folder of `adfkit suture --record`")
    dataset = root / "dataset" if (root / "dataset" / "index.jsonl").is_file() else root
    index = dataset / "index.jsonl"
    if not index.is_file():
        raise _fail(
            f"{inputs.shown(root)} holds no recorded frames (no dataset/index.jsonl)",
            root,
            "record one with `adfkit suture --record --out DIR`, then view DIR",
        )
    text = inputs.read_text(index, "text", tree=inputs.tree_of(root), what="episode index")
    by_step: dict[int, Frame] = {}
    for n, line in enumerate(text.splitlines(), 1):
        if not line.strip():
            continue
        try:
            d = json.loads(line)
            step = int(d["step"])
        except (ValueError, KeyError, TypeError) as exc:
            raise AdfError(
                error(
                    "bad-episode",
                    f"frame line {n} is not a frame record ({type(exc).__name__})",
                    SourceLocation(str(index), n, 1),
                    "the file is written by adfkit suture --record",
                )
            ) from None
        if step not in by_step:
            needle = np.asarray(d["needle"], dtype=float) if d.get("needle") is not None else None
            by_step[step] = Frame(
                step, float(d.get("time_s", 0.0)), str(d.get("phase", "")), needle, dict(d.get("psms") or {})
            )
    frames = [by_step[k] for k in sorted(by_step)]
    if not frames:
        raise _fail(f"{inputs.shown(index)} lists no frames", index, "record a longer episode")
    metrics: dict = {}
    mpath = root / "metrics.json"
    if mpath.is_file():
        try:
            metrics = json.loads(inputs.read_text(mpath, "text", tree=inputs.tree_of(root), what="metrics"))
        except ValueError:
            metrics = {}
    return Episode(root, frames, list(metrics.get("pairs") or []), metrics)
