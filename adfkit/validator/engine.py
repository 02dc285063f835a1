"""Validate ADF files: reader diagnostics, JSON Schema with positions, semantic and path rules.

``validate_file`` checks one file; ``validate_paths`` takes files and folders and follows a
launch file to everything it names (world, environment, input devices, colors, models),
checking each model's references against the models AMBF would have loaded before it.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field, replace
from pathlib import Path

from .. import inputs
from ..adf.reader import read_file
from ..adf.volume_labels import is_labels_file, parse_labels
from ..adf.yamlcompat import read_as_ambf
from ..adf.yamlnodes import read_text
from ..diagnostics import AdfError, Diagnostic, Severity, SourceLocation
from ..model import FILE_KINDS, Launch, ModelFile, World
from . import paths_check, schema_check, semantic

KIND_OF = {cls: name for name, cls in FILE_KINDS.items()}
YAML_SUFFIXES = (".yaml", ".yml")
LABELS_KIND = "volume-labels"  # not an ADF kind: a volume's labels.yaml (adf.volume_labels)
# Reader findings whose severity the validator sets from what AMBF does:
# duplicate keys load in AMBF (it keeps the first value; sb/cloth.yaml), so a warning.
SEVERITY_OVERRIDES = {"yaml-duplicate-key": Severity.WARNING}


@dataclass
class FileResult:
    path: Path
    kind: str | None = None
    doc: object = None
    diagnostics: list[Diagnostic] = field(default_factory=list)
    text: str | None = None


def _read_with_compat(path: Path, kind: str | None, text: str, roots: list, tree=None, referrer=None):
    """read_file, retrying layouts yaml-cpp accepts and PyYAML does not (adf.yamlcompat)."""
    return read_as_ambf(path, kind, text=text, root_out=roots, tree=tree, referrer=referrer)


def _adjust(d: Diagnostic) -> Diagnostic:
    sev = SEVERITY_OVERRIDES.get(d.rule)
    if sev is not None and d.severity != sev:
        return replace(d, severity=sev)
    if d.rule == "bad-bool" and d.message.startswith("'enable motor'"):
        # AMBF never converts `enable motor` (it reads `enable feedback` in its place).
        return replace(d, severity=Severity.WARNING, message=d.message + " (AMBF never reads this value)")
    return d


def validate_file(
    path: str | Path,
    kind: str | None = None,
    context_models=(),
    text: str | None = None,
    tree=None,
    referrer: SourceLocation | None = None,
) -> FileResult:
    """Check one file. ``tree``/``referrer``: the file was named by another one and must lie
    in that scene's tree (adfkit.inputs); None when the user named it."""
    path = Path(path)
    res = FileResult(path)
    try:
        if text is None:
            text = read_text(path, tree, referrer)
        res.text = text
        roots: list = []
        doc, reader_diags, text, moved = _read_with_compat(path, kind, text, roots, tree, referrer)
    except AdfError as exc:
        if kind is None and is_labels_file(path) and [d.rule for d in exc.diagnostics] == ["unknown-kind"]:
            return _labels(res)
        res.diagnostics = [_inside(_adjust(d), res.text) for d in exc.diagnostics]
        return res
    res.doc, res.text = doc, text
    res.kind = KIND_OF[type(doc)]
    diags = [_adjust(d) for d in reader_diags]
    root = roots[-1]
    located_errors = {d.location for d in diags if d.severity >= Severity.ERROR}
    for d in schema_check.check(root, res.kind, str(path)):
        if d.location not in located_errors:
            diags.append(d)
    diags += semantic.check(doc, context_models)
    diags += paths_check.check(doc)
    res.diagnostics = _unique(diags)
    return res


def _labels(res: FileResult) -> FileResult:
    """A volume's labels.yaml (adfkit drill's, in the slice folder: not ADF), checked as one."""
    res.kind = LABELS_KIND
    try:
        parse_labels(res.text or "", str(res.path))
    except AdfError as exc:
        res.diagnostics = [_inside(d, res.text) for d in exc.diagnostics]
    return res


def _inside(d: Diagnostic, text: str | None) -> Diagnostic:
    """PyYAML marks the end of a stream one line past the last one; point at the last line."""
    loc = d.location
    if text is None or loc is None or not loc.line:
        return d
    lines = text.split("\n")
    if text.endswith("\n") and len(lines) > 1:
        lines.pop()
    if loc.line > len(lines):
        return replace(d, location=SourceLocation(loc.file, len(lines), len(lines[-1]) + 1))
    return d


def _unique(diags: list[Diagnostic]) -> list[Diagnostic]:
    seen, out = set(), []
    for d in diags:
        key = (d.rule, d.location, d.message)
        if key not in seen:
            seen.add(key)
            out.append(d)
    return sorted(out, key=lambda d: (d.location.line if d.location else 0, d.location.column if d.location else 0))


def expand(paths) -> tuple[list[tuple[Path, inputs.Tree | None]], list[Diagnostic]]:
    """Files to check from command-line paths, each with the tree it must lie in: None for a
    file named on the command line, the folder's tree for files found in a named folder
    (searched recursively; a symlink found there that leads out of the folder is refused)."""
    files: list[tuple[Path, inputs.Tree | None]] = []
    problems: list[Diagnostic] = []
    for p in map(Path, paths):
        try:
            inputs.check_path_text(p)
            is_dir = p.is_dir()
        except AdfError as exc:
            problems += exc.diagnostics
            continue
        if is_dir:
            tree = inputs.Tree(Path(os.path.realpath(p)))
            files += [
                (f, tree) for f in sorted(f for f in p.rglob("*") if f.suffix.lower() in YAML_SUFFIXES and f.is_file())
            ]
        elif os.path.lexists(p):
            files.append((p, None))
        else:
            problems.append(
                Diagnostic(
                    Severity.ERROR,
                    "file-not-found",
                    f"no such file or folder: {inputs.shown(p)}",
                    SourceLocation(inputs.shown(p)),
                    "check the path",
                )
            )
    return files, problems


def validate_paths(paths, kind: str | None = None, follow: bool = True) -> tuple[list[FileResult], list[Diagnostic]]:
    files, problems = expand(paths)
    return validate_files(files, kind, follow), problems


def validate_files(files, kind: str | None = None, follow: bool = True) -> list[FileResult]:
    """Check ``files``, (path, tree) pairs as :func:`expand` gives them, launch files first."""
    results: dict[Path, FileResult] = {}

    def run(path: Path, k: str | None, context=(), tree=None, referrer=None) -> FileResult:
        key = Path(os.path.realpath(path))
        if key in results:
            return results[key]
        res = validate_file(path, k, context, tree=tree, referrer=referrer)
        results[key] = res
        if follow and isinstance(res.doc, World) and res.doc.environment:
            env = paths_check.relative_to_file(res.doc.path, res.doc.environment)
            if os.path.lexists(env):
                run(env, "model", tree=res.doc.tree, referrer=res.doc.where("environment"))
        if follow and isinstance(res.doc, Launch):
            follow_launch(res.doc)
        return res

    def follow_launch(launch: Launch) -> None:
        targets = paths_check.launch_targets(launch)
        context: list[ModelFile] = []
        for slot, k in (
            ("world config", "world"),
            ("input devices config", "input_devices"),
            ("color config", "colors"),
        ):
            for p in targets.get(slot, []):
                if os.path.lexists(p):
                    res = run(p, k, tree=launch.tree, referrer=launch.where(slot))
                    if k == "world" and isinstance(res.doc, World) and res.doc.cameras:
                        # the world's cameras: parents the models' cameras and lights may name
                        context.append(ModelFile(namespace=res.doc.namespace, cameras=list(res.doc.cameras)))
                    if k == "world" and isinstance(res.doc, World) and res.doc.environment:
                        env_path = paths_check.relative_to_file(res.doc.path, res.doc.environment)
                        try:  # a name no file can have (a NUL byte): the world's own check says so
                            env = results.get(Path(os.path.realpath(env_path)))
                        except (ValueError, OSError):
                            env = None
                        if env is not None and isinstance(env.doc, ModelFile):
                            context.append(env.doc)
        for p in targets.get("multibody configs", []):
            if os.path.lexists(p):
                res = run(p, "model", tuple(context), tree=launch.tree, referrer=launch.where("multibody configs"))
                if isinstance(res.doc, ModelFile):
                    context.append(res.doc)

    # Launch files first, so the models they name are checked with the models loaded before them.
    for f, tree in sorted(files, key=lambda ft: not _looks_like_launch(*ft)):
        run(f, kind, tree=tree)
    return list(results.values())


def in_engine_order(files) -> list:
    """``files`` in the order validate_files checks them: launch files first."""
    return sorted(files, key=lambda ft: not _looks_like_launch(*ft))


def chunked(files, parts: int) -> list[list]:
    """The files in the engine's order cut into ``parts`` contiguous chunks (fewer when there
    are fewer files)."""
    return _cut(in_engine_order(files), parts)


def _cut(files: list, parts: int) -> list[list]:
    n = max(1, min(len(files), parts))
    size = -(-len(files) // n) if files else 1
    return [files[i : i + size] for i in range(0, len(files), size)]


def merge_chunks(runs) -> list[FileResult]:
    """Chunks' results joined in order; a file reached twice is kept where it first appears,
    as the serial run keeps it."""
    results, seen = [], set()
    for chunk in runs:
        for res in chunk:
            key = Path(os.path.realpath(res.path))
            if key not in seen:
                seen.add(key)
                results.append(res)
    return results


def _chunk_without_docs(args) -> list[FileResult]:
    files, kind, follow = args
    out = validate_files(files, kind, follow)
    for res in out:
        res.doc = None  # the model stays in the worker: only findings and text travel back
    return out


def auto_jobs(n_files: int) -> int:
    """Processes worth starting for ``n_files``: one per CPU, but at least ~24 files each."""
    return max(1, min(os.cpu_count() or 1, n_files // 24))


def validate_files_jobs(files, kind: str | None = None, follow: bool = True, jobs: int = 0) -> list[FileResult]:
    """validate_files on ``jobs`` local processes (0: :func:`auto_jobs`), the same findings in
    the same order; the results carry no ``doc``. Forked workers start with everything already
    imported; where fork is not available it runs in this process."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    files = list(files)
    jobs = auto_jobs(len(files)) if jobs <= 0 else jobs
    if jobs <= 1 or len(files) < 2 or "fork" not in multiprocessing.get_all_start_methods():
        return validate_files(files, kind, follow)
    units = _work_units(files, follow, 4 * jobs)
    with ProcessPoolExecutor(jobs, mp_context=multiprocessing.get_context("fork")) as pool:
        runs = list(pool.map(_chunk_without_docs, [(c, kind, follow) for c in units]))
    return merge_chunks(runs)


def _work_units(files, follow: bool, parts: int) -> list[list]:
    """Each launch file alone (it checks the files it reaches), then the other files in
    contiguous chunks, less those a launch file reaches: the serial run checks those once, in
    the launch file's context, and so does this (no file is checked twice)."""
    if not follow:
        return chunked(files, parts)
    launch_flags = [_looks_like_launch(*ft) for ft in files]  # each file opened once to sniff it
    launches = [ft for ft, is_launch in zip(files, launch_flags) if is_launch]
    reached: set[str] = set()
    for path, tree in launches:
        reached |= _reached_from_launch(path, tree)
    rest = [
        ft for ft, is_launch in zip(files, launch_flags) if not is_launch and os.path.realpath(ft[0]) not in reached
    ]
    return [[ft] for ft in launches] + (_cut(rest, max(1, parts - len(launches))) if rest else [])


def _reached_from_launch(path: Path, tree) -> set[str]:
    """Real paths of the files validate_files follows from launch file ``path`` (its world and
    the world's environment, input devices, colours and models); empty when it cannot be read."""
    try:
        launch, _ = read_file(path, "launch", tree=tree)
    except AdfError:
        return set()
    if not isinstance(launch, Launch):
        return set()
    out: set[str] = set()
    for slot, paths in paths_check.launch_targets(launch).items():
        for p in paths:
            out.add(os.path.realpath(p))
            if slot == "world config" and os.path.lexists(p):
                try:
                    world, _ = read_file(p, "world", tree=launch.tree)
                except AdfError:
                    continue
                if isinstance(world, World) and world.environment:
                    out.add(os.path.realpath(paths_check.relative_to_file(world.path, world.environment)))
    return out


def _looks_like_launch(path: Path, tree=None) -> bool:
    try:
        with open(inputs.check_file(path, tree=tree), "rb") as fh:
            head = fh.read(65536).decode("utf-8", errors="replace")
    except (OSError, AdfError):
        return False
    return re.search(r"^(world config|multibody configs)\s*:", head, flags=re.M) is not None
