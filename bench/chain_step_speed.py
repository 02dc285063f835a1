"""CPU time of the PyBullet runner playing a robot's joint program as ``adfkit parity --commands``
plays it: AMBF's bodies, 1 ms control steps, every driven chain through AMBF's ten-sweep solver
step (runner/chain_rows.py, runner/pybullet/chain.py). The robots are the corpus KUKA and LND
400006 PSM, and the ECM and MTM (closed loops), with the programs ``adfkit.parity.programs`` writes (the dynamic-parity table's rows);
without ``../shared/corpus`` there is nothing to play and it says so.

    .venv/bin/python bench/chain_step_speed.py [--seconds S] [--rounds R] [--against REV]

The figure is this process's CPU time (``time.process_time``) of the stepping alone, per second
simulated, the median of R rounds on freshly built worlds; and the share of it in the chain step
(``ChainModel.velocities``), by cProfile on one more round; and a digest of every body's state at
the end of the first round (a change that only reorganises the chain step keeps it to the bit).
With ``--against REV`` each round plays each program with this tree's adfkit and with git revision
REV's (bench/against.py: fresh processes, alternated round by round, so both see the same load)
and prints both medians, their ratio and whether the final states agree.
Prints figures, asserts nothing.
"""

from __future__ import annotations

import argparse
import cProfile
import hashlib
import json
import pstats
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))
CORPUS = ROOT.parent / "shared" / "corpus"
#: the file of ChainModel.velocities, whose cumulative time is the chain step's
MODEL = str(Path("pybullet") / "chain.py")
ROBOTS = (
    ("KUKA", "ambf/ambf_models/descriptions/multi-bodies/robots/blender-kuka.yaml", "velocity"),
    ("PSM (LND 400006)", "src/ADF/PSMs/LND_400006_SIMPLE/psm1.yaml", "position"),
    ("PSM (LND 400006)", "src/ADF/PSMs/LND_400006_SIMPLE/psm1.yaml", "velocity"),
    ("ECM (loops)", "ambf/ambf_models/descriptions/multi-bodies/robots/blender-ecm.yaml", "velocity"),
    ("MTM (loop)", "ambf/ambf_models/descriptions/multi-bodies/robots/blender-mtm.yaml", "position"),
)


def _player(model: Path, kind: str, folder: Path):
    from adfkit.adf import load_scene
    from adfkit.parity import commandfile, programs
    from adfkit.parity.traces import AdfkitPlayer
    from adfkit.runner import Options, open_world

    cmd = programs.write_program(model, None, kind, 1.0, folder / f"{model.stem}_{kind}.txt")
    opt = Options(control_substeps=1, visuals=False, renderer="tiny")
    opt.ghosts, opt.springs, opt.link_shapes, opt.bodies = "ambf", "ambf", "body", "ambf"
    world = open_world(load_scene(model, None, []), opt, engine="pybullet")
    player = AdfkitPlayer(world)
    return world, player, commandfile.resolved(commandfile.read(cmd), player.made)


def one_round(robot: int, seconds: float, folder: Path) -> tuple[float, str]:
    """(CPU seconds per simulated second, digest of every body's final state) of one program."""
    _label, rel, kind = ROBOTS[robot]
    world, player, cmds = _player(CORPUS / rel, kind, folder)
    try:
        t0 = time.process_time()
        player.play(seconds, 0.02, cmds)
        cpu = (time.process_time() - t0) / seconds
        return cpu, hashlib.sha256(repr([sb.state() for sb in world.bodies]).encode()).hexdigest()[:12]
    finally:
        world.close()


def against(rev: str, seconds: float, rounds: int) -> int:
    """Each program with this tree's adfkit and REV's, in fresh processes, alternated."""
    from against import alternated

    print(f"| robot | program | this tree, CPU s per simulated s (median) | {rev} | ratio | final states |")
    print("|---|---|---|---|---|---|")
    for robot, (label, _rel, kind) in enumerate(ROBOTS):

        def played(tree: str, robot: int = robot) -> dict:
            cmd = [sys.executable, __file__, "--seconds", str(seconds), "--child", tree, "--robot", str(robot)]
            out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
            return json.loads(out.strip().splitlines()[-1])

        got = alternated(rev, rounds, played)
        new, base = (statistics.median(r["cpu"] for r in got[k]) for k in ("this tree", rev))
        same = {r["digest"] for rows in got.values() for r in rows}
        agree = "the same to the bit" if len(same) == 1 else "differ: " + ", ".join(sorted(same))
        print(f"| {label} | {kind} | {new:.2f} s | {base:.2f} s | {new / base:.3f} | {agree} |")
    return 0


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=1.0)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--against", metavar="REV", help="time this tree's chain step against git revision REV's")
    ap.add_argument("--child", help=argparse.SUPPRESS)  # (--against's rounds: the adfkit to import)
    ap.add_argument("--robot", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if not CORPUS.is_dir():
        print(f"skipped: no corpus at {CORPUS} (the robots played are the corpus's)")
        return 0
    if args.child:
        from against import use_tree

        use_tree(args.child)
        with tempfile.TemporaryDirectory(prefix="adfkit-chain-bench-") as tmp:
            cpu, digest = one_round(args.robot, args.seconds, Path(tmp))
        print(json.dumps({"cpu": cpu, "digest": digest}))
        return 0
    if args.against:
        return against(args.against, args.seconds, args.rounds)
    print("| robot | program | CPU s per simulated s (median) | rounds | in the chain step | final states |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory(prefix="adfkit-chain-bench-") as tmp:
        for robot, (label, rel, kind) in enumerate(ROBOTS):
            cpu, digests = [], []
            for _ in range(args.rounds):
                c, digest = one_round(robot, args.seconds, Path(tmp))
                cpu.append(c)
                digests.append(digest)
            world, player, cmds = _player(CORPUS / rel, kind, Path(tmp))
            prof = cProfile.Profile(time.process_time)
            prof.enable()
            player.play(args.seconds, 0.02, cmds)
            prof.disable()
            world.close()
            stats = pstats.Stats(prof).stats  # type: ignore[attr-defined]
            total = sum(s[2] for s in stats.values())
            # ChainModel.velocities alone (its ChainStep.velocities, of the same name, is inside it)
            chain = sum(s[3] for (f, _l, name), s in stats.items() if name == "velocities" and f.endswith(MODEL))
            print(
                f"| {label} | {kind} | {statistics.median(cpu):.2f} s | {args.rounds} | "
                f"{100 * chain / total if total else 0:.0f} % | {digests[0]}{'' if len(set(digests)) == 1 else ' (rounds differ)'} |"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
