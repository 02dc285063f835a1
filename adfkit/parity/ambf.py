"""AMBF itself, run headless: find a built AMBF tree, build adfkit's AMBF plugin against it
(once, into the cache), and play a scene in ``ambf_simulator`` with the plugin recording what AMBF
created and where its bodies go, and driving it from a command file. AMBF's own output (its
banner, its ROS plugins failing without ROS, its mesh notes) goes to a log file, never to the
user's terminal."""

from __future__ import annotations

import fcntl
import hashlib
import json
import os
import shutil
import subprocess
import tempfile
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

from ..diagnostics import AdfError, error

PLUGIN_SOURCE = Path(__file__).with_name("ambf_plugin")
SIMULATOR = Path("bin") / "lin-x86_64" / "ambf_simulator"
#: AMBF's fixed physics step in every run here: -t true -p 100000 -s 100 gives dt = s/p = 1 ms, its
#: loop paced at up to 100 kHz (poses identical to -p 1000 and to -p 10000 -s 10, measured; at
#: 10 kHz a light scene waited on the pacing: the arm's 1000 steps took 0.100 s, now 0.010 s)
PHYSICS_FLAGS = ("-g", "false", "-t", "true", "-p", "100000", "-s", "100")
DT = 0.001
#: Bullet's solver iterations a step in AMBF when nothing sets them: Bullet's default, which AMBF keeps
DEFAULT_SOLVER_ITERATIONS = 10
#: the plugin's knob that sets them (``adfkit parity --ambf-iterations N`` sets it for its runs)
ITERATIONS_ENV = "ADFKIT_PARITY_SOLVER_ITERATIONS"
#: the hint beside a count read_iterations refuses
ITERATIONS_HINT = (
    "a whole number, 1 or more (10: AMBF's own; 50: adfkit's suture's), or leave --ambf-iterations out "
    "(AMBF's own 10; with --suture the suture's 50)"
)


def read_iterations(text: str) -> int | None:
    """``--ambf-iterations``'s count (None: not a positive whole number)."""
    try:
        n = int(text.strip())
    except ValueError:
        return None
    return n if n > 0 else None


def iterations_in_environment() -> bool:
    """Whether the plugin's knob holds a count (set by the user, or by iterations_set)."""
    return read_iterations(os.environ.get(ITERATIONS_ENV, "")) is not None


def iterations_for(given: int | None, suture: bool) -> tuple[int | None, str]:
    """The solver iterations to set for AMBF's runs (None: leave the environment as it is) and
    where they come from: ``given`` (``--ambf-iterations``), else the plugin's knob where it is
    set, else for a suture's replay the iterations the suture records with (both sides then solve
    alike, as a scene's plain parity does at AMBF's own), else AMBF's own."""
    if given is not None:
        return given, "--ambf-iterations"
    if iterations_in_environment():
        return None, f"${ITERATIONS_ENV}"
    if suture:
        from ..tasks.episode import SOLVER_ITERATIONS

        return SOLVER_ITERATIONS, "the suture's own, as adfkit records it; --ambf-iterations 10 for AMBF's default"
    return None, "AMBF's default"


def solver_iterations() -> int:
    """The solver iterations AMBF runs here: the plugin's knob where it holds a positive count,
    else AMBF's own."""
    return read_iterations(os.environ.get(ITERATIONS_ENV, "")) or DEFAULT_SOLVER_ITERATIONS


@contextmanager
def iterations_set(n: int | None) -> Iterator[int]:
    """Every AMBF run inside plays ``n`` solver iterations a step (None: as the environment says,
    AMBF's own 10 unless the knob is set); yields the count AMBF plays."""
    if n is None:
        yield solver_iterations()
        return
    before = os.environ.get(ITERATIONS_ENV)
    os.environ[ITERATIONS_ENV] = str(n)
    try:
        yield n
    finally:
        if before is None:
            os.environ.pop(ITERATIONS_ENV, None)
        else:
            os.environ[ITERATIONS_ENV] = before


def cache_root() -> Path:
    """adfkit's cache (``$XDG_CACHE_HOME/adfkit``, else ``~/.cache/adfkit``)."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "adfkit"


def default_dir() -> Path:
    """Where ``make ambf`` builds AMBF: the AMBF source tree inside the cache."""
    return cache_root() / "ambf-build" / "ambf"


@dataclass(frozen=True)
class AmbfBuild:
    """A built AMBF source tree, as AMBF's own build leaves it."""

    root: Path

    @property
    def simulator(self) -> Path:
        return self.root / SIMULATOR

    @property
    def cmake_dir(self) -> Path:
        return self.root / "build"


def problem(root: Path) -> str | None:
    """Why ``root`` is not a built AMBF tree, or None."""
    if not root.is_dir():
        return f"{root} is not a folder"
    sim = root / SIMULATOR
    if not (sim.is_file() and os.access(sim, os.X_OK)):
        return f"{root} has no {SIMULATOR} (AMBF's build makes it)"
    if not (root / "build" / "AMBFConfig.cmake").is_file():
        return f"{root} has no build/AMBFConfig.cmake (the plugin is built against it)"
    return None


def find_build(path: str | os.PathLike | None) -> AmbfBuild:
    """The AMBF tree at ``path`` (None: ``$ADFKIT_AMBF``, else the one ``make ambf`` builds);
    a located error with the way to get one when there is none."""
    root = Path(path or os.environ.get("ADFKIT_AMBF") or default_dir()).expanduser().resolve()
    why = problem(root)
    if why is not None:
        raise AdfError(
            error(
                "ambf-missing",
                f"--ambf: {why}",
                None,
                "give a built AMBF source tree (bin/lin-x86_64/ambf_simulator and build/), "
                "or run `make ambf` to build AMBF 2.0 from ../shared/ambf into the cache",
            )
        )
    return AmbfBuild(root)


def available() -> tuple[AmbfBuild | None, str]:
    """(the default AMBF build, "") or (None, why not): what the tests skip on."""
    root = Path(os.environ.get("ADFKIT_AMBF") or default_dir()).expanduser()
    why = problem(root)
    if why is not None:
        return None, f"no AMBF build ({why}; `make ambf` builds one)"
    return AmbfBuild(root.resolve()), ""


def _plugin_key(build: AmbfBuild) -> str:
    h = hashlib.sha256()
    for f in sorted(PLUGIN_SOURCE.iterdir()):
        h.update(f.name.encode() + b"\0" + f.read_bytes())
    h.update(str(build.root).encode())
    lib = build.cmake_dir / "libambf_framework.a"
    h.update(str(lib.stat().st_mtime_ns if lib.exists() else 0).encode())
    return h.hexdigest()[:16]


def plugin_library(build: AmbfBuild) -> Path:
    """adfkit's AMBF plugin built against ``build`` (CMake, once per plugin source and AMBF
    build, into the cache; a lock keeps two processes from building it at once)."""
    out = cache_root() / "ambf-plugin" / _plugin_key(build)
    lib = out / "libadfkit_parity.so"
    if lib.is_file():
        return lib
    out.mkdir(parents=True, exist_ok=True)
    with open(out / ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if lib.is_file():
            return lib
        if shutil.which("cmake") is None:
            raise AdfError(error("ambf-plugin", "cmake is not installed: adfkit's AMBF plugin cannot be built", None))
        work = out / "build"
        log = out / "build.log"
        with open(log, "w") as f:
            steps = (
                ["cmake", "-S", str(PLUGIN_SOURCE), "-B", str(work), f"-DAMBF_DIR={build.cmake_dir}"]
                + ["-DCMAKE_BUILD_TYPE=Release"],
                ["cmake", "--build", str(work), "-j", "2"],
            )
            for cmd in steps:
                if subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT).returncode != 0:
                    raise AdfError(
                        error(
                            "ambf-plugin",
                            f"adfkit's AMBF plugin did not build against {build.root}",
                            None,
                            f"the build's output is in {log}",
                        )
                    )
        shutil.copy2(work / "libadfkit_parity.so", lib.with_suffix(".tmp"))
        os.replace(lib.with_suffix(".tmp"), lib)
    return lib


@dataclass
class Command:
    """One line of the plugin's command file: at ``t`` seconds, ``kind`` (position, velocity,
    effort, grasp, release, place, force, pose, collide; follow: a point of a joint's path) on
    ``target`` (a joint's, an actuator's or a body's AMBF name) with ``value`` (a joint
    command's, a path point's position; a collide's 0 or 1), ``body`` (a grasp's or a collide's
    other body) or ``numbers``."""

    t: float
    kind: str
    target: str
    value: float = 0.0
    body: str = ""
    numbers: tuple = ()  # place, pose: the body frame (x y z qx qy qz qw); force: (fx fy fz px py pz) in the world;
    # grasp: none (the body held where it lies) or its frame in the actuator's parent's frame (held there)

    def line(self) -> str:
        if self.kind in ("place", "force", "pose"):
            arg = " ".join(repr(float(v)) for v in self.numbers)
        elif self.kind == "grasp" and self.numbers:
            arg = " ".join([self.body] + [repr(float(v)) for v in self.numbers])
        elif self.kind == "collide":
            arg = f"{self.body} {int(self.value)}"
        else:
            arg = self.body if self.kind == "grasp" else ("" if self.kind == "release" else repr(float(self.value)))
        return f"{self.t!r} {self.kind} {self.target} {arg}".rstrip()


@dataclass
class AmbfRecord:
    """What the plugin wrote: what AMBF created and the samples (time, poses, joint values)."""

    created: dict
    samples: list[dict]
    wall_s: float  # AMBF's stepping alone (the plugin's clock, first step to last)
    process_s: float  # the whole ambf_simulator process, loading included
    log: str = field(repr=False, default="")
    end: dict = field(default_factory=dict)  # the plugin's end record (a paced replay's "pace")

    def body_names(self) -> list[str]:
        return [b["qname"] for b in self.created["bodies"]]


@dataclass
class Stage:
    """How AMBF is asked to load a scene: a launch file and the indices of its models."""

    launch: Path
    indices: list[int]
    keep: tempfile.TemporaryDirectory | None = None  # a launch written for a world or model file
    staged_bodies: tuple[str, ...] = ()  # bodies of the stage's own (the floor), not of the scene


#: the name of the floor a stage gives a model played alone (``_floor_model``)
FLOOR_NAME = "/ambf/env/adfkit_floor"


def write_stage(world: Path | None, models: Sequence[Path], floor_z: float | None) -> Stage:
    """A launch file for AMBF naming ``world`` (None: a world of its own, with a floor plane at
    ``floor_z`` as adfkit's runner gives a model played alone, or an empty environment) and
    ``models``. AMBF's launch files need a world, an input-devices and a colour file, and its
    world needs an environment (without one the simulator crashes)."""
    tmp = tempfile.TemporaryDirectory(prefix="adfkit-parity-")
    d = Path(tmp.name)
    (d / "input_devices.yaml").write_text("input devices: []\n")
    (d / "colors.yaml").write_text("{}\n")
    if world is None:
        if floor_z is None:
            (d / "environment.yaml").write_text("bodies: []\njoints: []\n")
        else:
            (d / "environment.yaml").write_text(_floor_model(floor_z))
        (d / "world.yaml").write_text(
            "enclosure size: {length: 10.0, width: 10.0, height: 3.0}\nlights: []\ncameras: []\n"
            "environment: environment.yaml\n"
        )
        world = d / "world.yaml"
    launch = {
        "world config": str(world),
        "color config": "colors.yaml",
        "input devices config": "input_devices.yaml",
        "multibody configs": [str(m) for m in models],
    }
    (d / "launch.yaml").write_text(json.dumps(launch, indent=1) + "\n")  # JSON is YAML
    return Stage(d / "launch.yaml", list(range(len(models))), tmp, (FLOOR_NAME,) if floor_z is not None else ())


def on_ambfs_floor(build: AmbfBuild, model: Path, folder: Path) -> Path | None:
    """A launch file in ``folder`` playing ``model`` in AMBF's own world (its checkered floor,
    from the AMBF tree), for AMBF and adfkit alike; None where the tree has no world file."""
    world = build.root / "ambf_models" / "descriptions" / "world" / "world.yaml"
    if not world.is_file():
        return None
    (folder / "colors.yaml").write_text("{}\n")
    (folder / "input_devices.yaml").write_text("input devices: []\n")
    launch = folder / f"{model.stem}_on_floor.yaml"
    launch.write_text(
        f"world config: {world}\ncolor config: colors.yaml\ninput devices config: input_devices.yaml\n"
        f"multibody configs: [{model}]\n"
    )
    return launch


def _floor_model(z: float) -> str:
    """A static PLANE at height ``z``: adfkit's floor under a model played alone (pybullet/
    assemble.py: PyBullet's default friction 0.5, no restitution)."""
    return (
        "bodies: [BODY adfkit_floor]\njoints: []\nnamespace: /ambf/env/\n"
        "BODY adfkit_floor:\n  name: adfkit_floor\n  mass: 0.0\n"
        f"  location: {{position: {{x: 0.0, y: 0.0, z: {z!r}}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}\n"
        "  collision shape: PLANE\n"
        "  collision geometry: {normal: {x: 0.0, y: 0.0, z: 1.0}, offset: 0.0}\n"
        "  friction: {static: 0.5, rolling: 0.0}\n  restitution: 0.0\n"
    )


def run(
    build: AmbfBuild,
    stage: Stage,
    seconds: float,
    every: float,
    commands: Sequence[Command] = (),
    timeout: float | None = None,
    pace: tuple[float, float, float] | None = None,
    pace_max_s: float | None = None,
    follow_gain: float | None = None,
) -> AmbfRecord:
    """Play ``stage`` in ``ambf_simulator`` for ``seconds`` (0: load only), a sample every
    ``every`` seconds, driven by ``commands``; AMBF's output goes to a log kept with the record.
    ``pace`` (rad, m, wait s): the commands read on the plugin's paced command clock, which
    advances only while the joints under position commands stand within those tolerances of
    their set-points (``seconds`` and ``every`` are then that clock's), ending at ``pace_max_s``
    of AMBF's time if the clock has not reached ``seconds`` by then. ``follow_gain`` (1/s): the
    feedback gain of the joints following a path (``follow`` commands; None: the plugin's)."""
    lib = plugin_library(build)
    with tempfile.TemporaryDirectory(prefix="adfkit-ambf-") as tmp:
        out = Path(tmp) / "record.jsonl"
        env = dict(os.environ, ADFKIT_PARITY_OUT=str(out), ADFKIT_PARITY_SECONDS=repr(float(seconds)))
        env["ADFKIT_PARITY_EVERY"] = repr(float(every))
        for key in ("ADFKIT_PARITY_PACE", "ADFKIT_PARITY_PACE_MAX", "ADFKIT_PARITY_FOLLOW_GAIN"):
            env.pop(key, None)
        if follow_gain is not None:
            env["ADFKIT_PARITY_FOLLOW_GAIN"] = repr(float(follow_gain))
        if pace is not None:
            env["ADFKIT_PARITY_PACE"] = " ".join(repr(float(v)) for v in pace)
            if pace_max_s is not None:
                env["ADFKIT_PARITY_PACE_MAX"] = repr(float(pace_max_s))
        if commands:
            cmd_file = Path(tmp) / "commands.txt"
            cmd_file.write_text("".join(c.line() + "\n" for c in commands))
            env["ADFKIT_PARITY_COMMANDS"] = str(cmd_file)
        argv = [str(build.simulator), *PHYSICS_FLAGS, "--launch_file", str(stage.launch)]
        if stage.indices:
            argv += ["-l", ",".join(str(i) for i in stage.indices)]
        argv += ["--plugins", str(lib)]
        log_path = Path(tmp) / "ambf.log"
        t0 = time.perf_counter()
        with open(log_path, "w") as log:
            try:
                proc = subprocess.run(
                    argv,
                    stdout=log,
                    stderr=subprocess.STDOUT,
                    stdin=subprocess.DEVNULL,
                    env=env,
                    cwd=stage.launch.parent,
                    timeout=timeout if timeout is not None else 120 + 20 * seconds,
                )
                rc = proc.returncode
            except subprocess.TimeoutExpired:
                rc = None
        process_s = time.perf_counter() - t0
        log_text = log_path.read_text(errors="replace")
        recs = [json.loads(line) for line in out.read_text().splitlines() if line.strip()] if out.exists() else []
    return _record(recs, rc, process_s, log_text, seconds)


def _record(recs: list[dict], rc: int | None, process_s: float, log: str, seconds: float) -> AmbfRecord:
    err = next((r for r in recs if r.get("kind") == "error"), None)
    if err is not None:
        raise AdfError(error("ambf-command", f"AMBF's plugin: {err['message']}", None))
    created = next((r for r in recs if r.get("kind") == "created"), None)
    end = next((r for r in recs if r.get("kind") == "end"), None)
    if created is None or end is None:
        how = "did not finish in time" if rc is None else f"stopped (exit status {rc})"
        tail = " | ".join(line for line in log.splitlines()[-4:] if line.strip())
        raise AdfError(
            error(
                "ambf-failed",
                f"ambf_simulator {how} before {seconds:g} s of the scene were played: {tail[:400]}",
                None,
                "AMBF's output is above; `adfkit validate` the scene",
            )
        )
    samples = [r for r in recs if r.get("kind") == "sample"]
    return AmbfRecord(created, samples, float(end.get("wall_s") or 0.0), process_s, log, end)
