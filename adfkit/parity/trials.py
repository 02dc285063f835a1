"""A suture's verdicts in AMBF as rates (``adfkit parity --suture --trials K``): the one recording
replayed K times in AMBF, the first as recorded and each other one nudged, every PSM joint's path
and set-points offset by a constant of ``Nudge.rad`` (revolute) or ``Nudge.m`` (prismatic), its
sign drawn at random per joint and trial. AMBF repeats a replay byte for byte, so the spread of
its verdicts over the nudges says how far one replay's verdict is determined by what adfkit's arms
did, and how far by the chaos of a thread pulled through holes: where a pair's verdict flips under
a nudge far under AMBF's own tracking error, the parity figure is the rate, not one run."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from . import ambf
from .suture import Recording, judged, record, replay


@dataclass(frozen=True)
class Nudge:
    """A trial's offset of every PSM joint: ``rad`` on a revolute joint, ``m`` on a prismatic one
    (1e-4 rad moves the tool 0.01-0.04 mm on the corpus PSM's 0.1-0.4 m levers, 1e-5 m the
    insertion 0.01 mm), far under AMBF's own median 0.3-1.0 mrad from adfkit's path."""

    rad: float = 1e-4
    m: float = 1e-5


NUDGE = Nudge()


def nudged(rec: Recording, nudge: Nudge, rng: np.random.Generator) -> list[ambf.Command]:
    """The recording's commands with each PSM joint's set-points and measured path (``position``
    and ``follow`` lines) offset by ``±nudge`` (one random sign per joint)."""
    joints = sorted({c.target for c in rec.commands if c.kind in ("position", "follow")})
    signs = dict(zip(joints, rng.choice((-1.0, 1.0), len(joints)), strict=True))
    out = []
    for c in rec.commands:
        if c.kind in ("position", "follow"):
            size = nudge.m if c.target in rec.prismatic else nudge.rad
            c = replace(c, value=c.value + signs[c.target] * size)
        out.append(c)
    return out


def compare_trials(
    launch,
    indices,
    pairs,
    build: ambf.AmbfBuild,
    count: int,
    nudge: Nudge = NUDGE,
    seed: int = 0,
    progress: bool = False,
    options: dict | None = None,
    grasp: str = "lies",
) -> dict:
    """``suture.compare_suture``'s JSON for the replay following adfkit's measured joints, with
    ``trials``: the same recording replayed ``count`` times in all, all but the first nudged."""
    rec = record(launch, indices, pairs, seed, progress, measured=True, options=options)
    first = replay(rec, build, launch, indices, None, "measured", grasp)
    out = judged(rec, [first]) | {"scene": str(launch), "seed": seed}
    out["trials"] = trials(
        rec, first.verdicts, first.gaps, build, launch, indices, count, nudge, "measured", seed, grasp
    )
    return out


def trials(
    rec: Recording,
    first: list[dict],
    first_gaps: dict[int, float],
    build: ambf.AmbfBuild,
    launch,
    indices,
    count: int,
    nudge: Nudge = NUDGE,
    follow: str = "measured",
    seed: int = 0,
    grasp: str = "lies",
) -> dict:
    """The recording replayed ``count`` times in all: ``first`` (the verdicts of the replay as
    recorded, ``first_gaps`` its tip gaps) and ``count - 1`` nudged replays (the signs drawn from
    ``seed``), per pair AMBF's verdicts and rules in trial order, how many of them are adfkit's
    verdict and the tip gaps."""
    rng = np.random.default_rng(seed)
    runs = [(first, first_gaps)]
    for _ in range(count - 1):
        r = replay(replace(rec, commands=nudged(rec, nudge, rng)), build, launch, indices, None, follow, grasp)
        runs.append((r.verdicts, r.gaps))
    return rates(rec.verdicts, runs) | {"count": count, "nudge": {"rad": nudge.rad, "m": nudge.m}, "seed": seed}


def rates(mine: list[dict], runs: list[tuple[list[dict], dict[int, float]]]) -> dict:
    """Per pair, adfkit's verdict beside AMBF's over the runs (each ``(verdicts, tip gaps)``): how
    often AMBF gives adfkit's verdict, and whether AMBF's own verdict (or rule) changes from run to
    run."""
    by_pair = {v["pair"]: v for v in mine}
    pairs = []
    for k, v in enumerate(runs[0][0]):
        a = by_pair.get(v["pair"], {})
        verdicts = [r[0][k]["verdict"] for r in runs]
        rules = [r[0][k]["rule"] for r in runs]
        gaps = [r[1].get(v["pair"]) for r in runs]
        same = sum(x == a.get("verdict", "not-tried") for x in verdicts)
        pairs.append(
            {
                "pair": v["pair"],
                "adfkit": a.get("verdict", "not-tried"),
                "adfkit_rule": a.get("rule"),
                "ambf": verdicts,
                "ambf_rules": rules,
                "same": same,
                "same_rate": same / len(runs),
                "ambf_flips": len(set(zip(verdicts, rules, strict=True))) > 1,
                "tip_path_gap_m": gaps,
            }
        )
    return {"pairs": pairs, "same_rate": float(np.mean([p["same_rate"] for p in pairs])) if pairs else 0.0}
