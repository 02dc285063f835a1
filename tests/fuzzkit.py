"""A seeded mutation fuzzer for adfkit's commands (issue 14), driven in process.

Seeds: small hand-written scenes (a model with joints, a sensor and a mesh; a launch with
world and models; a URDF; an MJCF), the bundled sample scene and, when present, the corpus.
Each case mutates one seed with one operator (type swaps, deletions, dangling references,
non-finite numbers, deep nesting, alias bombs, tags, odd bytes, long and odd paths, device
files, symlinks out of the tree, non-text keys, duplicates, hostile XML, garbage meshes),
writes it into a fresh scene folder, and runs one command on it through ``adfkit.cli.main``
(stdout/stderr captured, a per-case timer). :func:`check` states what must hold whatever the
input: exit 0/1/2, no traceback, a located ``error[rule]`` for exit 2, strict JSON, nothing
opened outside the scene's tree (an audit hook records every ``open``) and no byte of the
planted secret or of /etc/passwd in any output.

Case ``i`` of seed ``s`` is the same on every machine: ``random.Random(f"{s}:{i}")``.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import random
import re
import signal
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SECRET = "ADFKIT-CANARY-7f3a9c"
PASSWD_MARK = "root:x:0:0"
LOCATED = re.compile(r"^(?P<file>[^\n]+?)(?::(?P<line>\d+):(?P<col>\d+))?: error\[(?P<rule>[a-z0-9-]+)\]: ", re.M)

from fuzz_mutations import (  # noqa: F401 - re-exported: the suite's one entry point is fuzzkit
    BROKEN_MESHES,
    HOSTILE_PATHS,
    XML_OPS,
    YAML_OPS,
    _plants,
    static_broken_mesh,
)
from fuzz_seeds import (  # noqa: F401
    SMALL_DEVICES,
    SMALL_FLOOR,
    SMALL_LAUNCH,
    SMALL_MJCF,
    SMALL_MODEL,
    SMALL_MODEL2,
    SMALL_STL,
    SMALL_URDF,
    SMALL_WORLD,
    Seed,
    builtin_seeds,
    corpus_seeds,
    sample_scene_seeds,
)

# ---------------------------------------------------------------------------------------------
# Cases


@dataclass
class Case:
    seed: str
    index: int
    op: str
    command: str
    files: dict[str, bytes]
    argv: list[str]  # "{dir}" and "{outside}" are filled in by run_case
    plants: dict = field(default_factory=dict)
    explicit: bool = False  # the hostile file is named on the command line itself

    @property
    def id(self) -> str:
        return f"{self.seed}#{self.index}:{self.op}:{self.command}"


def commands_for(seed: Seed, with_run: bool, with_blender: bool) -> list[tuple[str, list[str]]]:
    main = "{dir}/" + seed.main
    if seed.kind in ("urdf", "mjcf"):
        other = "mjcf" if seed.kind == "urdf" else "urdf"
        return [
            ("convert-adf", ["convert", main, "{dir}/out.yaml", "--json"]),
            ("convert-" + other, ["convert", main, "{dir}/out." + ("xml" if other == "mjcf" else "urdf"), "--json"]),
        ]
    cmds = [
        ("validate-text", ["validate", main]),
        ("validate-json", ["validate", "-f", "json", main]),
        ("validate-github", ["validate", "-f", "github", main]),
        ("validate-sarif", ["validate", "-f", "sarif", main]),
        ("info", ["info", main]),
        ("info-json", ["info", "--json", main]),
    ]
    if seed.kind == "launch":
        cmds += [("info-l", ["info", "-l", "0,1", main])]
    if seed.kind == "model" and seed.small:
        cmds += [
            ("convert-urdf", ["convert", main, "{dir}/out.urdf", "--json"]),
            ("convert-mjcf", ["convert", main, "{dir}/out.xml", "--json"]),
            ("convert-adf", ["convert", main, "{dir}/out.yaml"]),
        ]
    if with_run and seed.small:
        extra = ["-l", "0,1"] if seed.kind == "launch" else []
        cmds += [("run", ["run", main, *extra, "--seconds", "0.004", "--no-frames", "--out", "{dir}/run"])]
        cmds += [
            (
                "run-mujoco",
                ["run", main, *extra, "--engine", "mujoco", "--seconds", "0.004", "--no-frames", "--out", "{dir}/run"],
            )
        ]
    if with_blender and seed.kind == "model" and seed.small:
        cmds += [("blend-import", ["blend-import", main, "{dir}/out.blend"])]
    return cmds


def make_case(seed: Seed, index: int, with_run: bool = True, with_blender: bool = False) -> Case:
    rng = random.Random(f"{seed.name}:{index}")
    ops = XML_OPS if seed.kind in ("urdf", "mjcf") else YAML_OPS
    op = rng.choice(sorted(ops))
    files, plants = ops[op](rng, dict(seed.files), seed)
    if rng.random() < 0.1:  # a second mutation on top
        op2 = rng.choice(sorted(ops))
        files, more = ops[op2](rng, files, seed)
        plants = plants or more
        op = f"{op}+{op2}"
    name, argv = rng.choice(commands_for(seed, with_run, with_blender))
    return Case(seed.name, index, op, name, files, argv, plants)


def explicit_cases() -> list[Case]:
    """Hostile files named on the command line itself: refused at once (devices, FIFOs,
    folders, bad path text) or read because the user named them (a regular file anywhere)."""
    out = []
    for i, target in enumerate(
        [
            "/dev/zero",
            "/dev/stdin",
            "/dev/urandom",
            "{dir}/fifo.yaml",
            "{dir}/folder",
            "{dir}/a\0b.yaml",
            "{dir}/" + "x" * 300 + ".yaml",
            "{dir}/nope.yaml",
            "{dir}/link_out.yaml",
            "{dir}/" + "d/" * 3000 + "m.yaml",
        ]
    ):
        for cmd in (
            ["validate"],
            ["validate", "-f", "json"],
            ["info"],
            ["info", "-l", "0"],
            ["run", "--seconds", "0.004"],
            ["convert", "{target}", "{dir}/out.urdf"],
        ):
            argv = [a.replace("{target}", target) for a in cmd] if "{target}" in cmd else [*cmd, target]
            out.append(
                Case(
                    "explicit",
                    i,
                    "named",
                    " ".join(cmd[:2]).replace("{target}", "").strip(),
                    {},
                    argv,
                    _plants(),
                    explicit=True,
                )
            )
    return out


# ---------------------------------------------------------------------------------------------
# Running and checking


class CaseTimeout(BaseException):
    """Raised by the timer in the main thread (a BaseException: no `except Exception` eats it)."""


_OPENED: list | None = None
_HOOKED = False


def _audit(event, args):
    if _OPENED is not None and event == "open" and args and isinstance(args[0], (str, bytes, os.PathLike)):
        _OPENED.append(args[0])


def _install_hook() -> None:
    global _HOOKED
    if not _HOOKED:
        sys.addaudithook(_audit)
        _HOOKED = True


@dataclass
class Outcome:
    case: Case
    rc: int | None
    out: str
    err: str
    error: str | None  # an exception that escaped main, or a timeout
    opened: list[str]
    scene: Path
    outside: Path
    left: list[str] = field(default_factory=list)  # temporary files the command left behind


def materialise(case: Case, scene: Path, outside: Path) -> None:
    scene.mkdir(parents=True, exist_ok=True)
    outside.mkdir(parents=True, exist_ok=True)
    (outside / "secret.yaml").write_text(f"bodies: [BODY {SECRET}]\nBODY {SECRET}:\n  name: {SECRET}\n  mass: 1\n")
    (outside / "secret.stl").write_text(SMALL_STL.replace("solid part", f"solid {SECRET}"))
    (outside / "secret.xml").write_text(
        f'<mujoco model="{SECRET}"><worldbody><body name="{SECRET}"/></worldbody></mujoco>\n'
    )
    for name, data in case.files.items():
        p = scene / name
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_bytes(data)
    for name, target in case.plants.get("symlinks", {}).items():
        with contextlib.suppress(OSError):
            os.symlink(target.replace("{outside}", str(outside)), scene / name)
    for name in case.plants.get("fifos", []):
        with contextlib.suppress(OSError):
            os.mkfifo(scene / name)
    for name in case.plants.get("dirs", []):
        (scene / name).mkdir(exist_ok=True)


def _fill(text: str, scene: Path, outside: Path) -> str:
    return text.replace("{dir}", str(scene)).replace("{outside}", str(outside))


def run_case(case: Case, workdir: Path, timeout: float = 20.0) -> Outcome:
    """Write the case into workdir/scene (with workdir/outside holding the secret), run it."""
    from adfkit.cli import main

    global _OPENED
    _install_hook()
    scene, outside = workdir / "scene", workdir / "outside"
    case = Case(
        case.seed,
        case.index,
        case.op,
        case.command,
        {k: v.replace(b"{outside}", str(outside).encode()) for k, v in case.files.items()},
        case.argv,
        case.plants,
        case.explicit,
    )
    materialise(case, scene, outside)
    argv = [_fill(a, scene, outside) for a in case.argv]
    tmpdir = workdir / "tmp"  # the command's $TMPDIR: empty when it returns
    tmpdir.mkdir(parents=True, exist_ok=True)
    old_tmp = tempfile.tempdir, os.environ.get("TMPDIR")
    tempfile.tempdir = os.environ["TMPDIR"] = str(tmpdir)
    out, err = io.StringIO(), io.StringIO()
    rc, error = None, None
    old_env = os.environ.get("ADFKIT_INPUT_ROOT")
    os.environ["ADFKIT_INPUT_ROOT"] = str(scene)  # the scene's tree is exactly its folder here

    def _alarm(_sig, _frame):
        raise CaseTimeout()

    old_handler = signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, timeout)
    _OPENED = []
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            rc = main(argv)
    except SystemExit as exc:  # argparse
        rc = exc.code if isinstance(exc.code, int) else 2
    except CaseTimeout:
        error = f"timeout after {timeout} s"
    except Exception as exc:  # noqa: BLE001 - exactly what the fuzzer hunts
        import traceback

        error = "".join(traceback.format_exception(exc))[-3000:]
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old_handler)
        opened = [os.fsdecode(p) if not isinstance(p, str) else p for p in _OPENED]
        _OPENED = None
        if old_env is None:
            os.environ.pop("ADFKIT_INPUT_ROOT", None)
        else:
            os.environ["ADFKIT_INPUT_ROOT"] = old_env
        tempfile.tempdir = old_tmp[0]
        if old_tmp[1] is None:
            os.environ.pop("TMPDIR", None)
        else:
            os.environ["TMPDIR"] = old_tmp[1]
    return Outcome(case, rc, out.getvalue(), err.getvalue(), error, opened, scene, outside, left_behind(tmpdir, scene))


#: what a writer puts beside its target until it renames it (adfkit.scratch, video.py, ...)
BESIDE = re.compile(r"^\..+\.\d+\..*\.tmp(\.npz)?$|^\..+\.\d+\.[^/]*$|\.part\.|\.tmp\.png$")


def left_behind(tmpdir: Path, scene: Path) -> list[str]:
    """Every file or folder in the command's $TMPDIR, and every temporary file beside a target
    in the scene's folder."""
    left = [str(p) for p in sorted(tmpdir.iterdir())] if tmpdir.is_dir() else []
    bpy = sys.modules.get("bpy")  # Blender's session folder lives as long as bpy (gone at exit)
    live = os.path.realpath(bpy.app.tempdir) if bpy is not None and getattr(bpy, "app", None) else None
    left = [p for p in left if os.path.realpath(p) != live]
    for root, dirs, files in os.walk(scene):
        left += [os.path.join(root, n) for n in dirs + files if BESIDE.search(n)]
    return left


def _strict_json(text: str) -> object:
    def refuse(name):
        raise ValueError(f"non-standard JSON constant {name}")

    return json.loads(text, parse_constant=refuse)


FORBIDDEN_OPEN = ("/etc/passwd", "/proc/self/environ", "/dev/zero", "/dev/stdin")


def _located_error(o: Outcome) -> bool:
    """An error with a file (and line:col where the file has lines) in the command's own format."""
    if any(m.group("file").strip() for m in LOCATED.finditer(o.err + o.out)):
        return True
    if re.search(r"^::error file=[^,:]+", o.out, re.M):
        return True
    try:
        data = _strict_json(o.out)
    except ValueError:
        return False
    if isinstance(data, dict) and "diagnostics" in data:
        return any(d.get("severity") == "error" and d.get("file") for d in data["diagnostics"])
    if isinstance(data, dict) and "runs" in data:
        return any(r.get("level") == "error" and r.get("locations") for run in data["runs"] for r in run["results"])
    return False


def problems(o: Outcome) -> list[str]:
    """Everything wrong with one outcome (empty: the case passed)."""
    bad = []
    text = o.out + o.err
    if o.error:
        return [f"escaped: {o.error}"]
    if o.left:
        bad.append(f"left temporary files behind: {o.left[:3]}")
    if o.rc not in (0, 1, 2):
        bad.append(f"exit status {o.rc}")
    if "Traceback (most recent call last)" in text:
        bad.append("a traceback in the output")
    if o.rc == 2 and not _located_error(o):
        bad.append("exit 2 without a located error[rule] diagnostic")
    if not o.case.explicit:
        if SECRET in text:
            bad.append("the secret outside the scene's tree reached the output")
        for p in o.opened:
            real = os.path.realpath(p) if "\0" not in p else p
            if real.startswith(str(o.outside.resolve())) or real in FORBIDDEN_OPEN or p in FORBIDDEN_OPEN:
                bad.append(f"opened {p} outside the scene's tree")
    if PASSWD_MARK in text:
        bad.append("/etc/passwd content in the output")
    for p in o.opened:
        if os.path.realpath(p) in ("/dev/zero", "/dev/stdin", "/dev/urandom") or p.endswith("fifo.yaml"):
            bad.append(f"opened a device or FIFO: {p}")
    argv = o.case.argv
    if o.rc in (0, 1) and o.out.strip() and ("json" in " ".join(argv) or "sarif" in argv):
        try:
            _strict_json(o.out)
        except ValueError as exc:
            bad.append(f"stdout is not strict JSON: {exc}")
    report = o.scene / "run" / "report.json"
    if report.is_file():
        try:
            _strict_json(report.read_text())
        except ValueError as exc:
            bad.append(f"report.json is not strict JSON: {exc}")
    return bad


_FRAME = re.compile(r'File "[^"]*/((?:adfkit|addon)/[^"]+)", line \d+, in (\w+)')
_EXC = re.compile(r"^(\w+(?:Error|Exception|error))\b", re.M)


def crash_site(o: Outcome) -> tuple[str, str, str] | None:
    """(module, function, exception) of an exception that escaped: the innermost frame in
    adfkit/ or addon/."""
    if not o.error or o.error.startswith("timeout"):
        return None
    frames = _FRAME.findall(o.error)
    exc = _EXC.findall(o.error)
    if not frames or not exc:
        return None
    return frames[-1][0], frames[-1][1], exc[-1]


def tally(outcomes) -> dict:
    t = {"cases": 0, "exit 0": 0, "exit 1": 0, "exit 2": 0, "failed": 0}
    for o in outcomes:
        t["cases"] += 1
        if o.rc in (0, 1, 2):
            t[f"exit {o.rc}"] += 1
        if problems(o):
            t["failed"] += 1
    return t
