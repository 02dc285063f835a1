"""Every scene, every engine, every format: each sample scene and each corpus scene (every entry
of every corpus launch file with its world, and every corpus model file) is played briefly by
`adfkit run` in PyBullet and in MuJoCo, and each of their model files is converted to URDF and
to MJCF and loaded (PyBullet's loadURDF, MuJoCo's compiler). Whatever the input: no traceback;
the report is written; every finding is located; whatever an engine does not play is a
`not_played` entry beside its warning; a scene AMBF itself rejects (the corpus's urdf-*.yaml)
is a located exit 2. The sample scenes and the corpus launch files run by default (about a
minute); every corpus model file too with `-m slow`."""

from __future__ import annotations

import contextlib
import io
import json
import re
from pathlib import Path

import pytest
from conftest import CORPUS, ROOT

pytest.importorskip("mujoco")
pb = pytest.importorskip("pybullet")

from adfkit.adf import read_file  # noqa: E402
from adfkit.cli import main  # noqa: E402
from adfkit.diagnostics import AdfError  # noqa: E402
from adfkit.model import Launch, ModelFile  # noqa: E402

SAMPLES = sorted(p / "launch.yaml" for p in (ROOT / "sample_scenes").iterdir() if (p / "launch.yaml").is_file())
#: a finding's first line: `file[:line:col]: severity[rule]: message`
FINDING = re.compile(r"^(?P<where>.*?): (?P<sev>error|warning|info)\[(?P<rule>[a-z0-9-]+)\]: (?P<msg>.*)$")
UNLOCATED = re.compile(r"^(error|warning|info)\[")
#: what an engine leaves out of a scene: each such warning has a not_played entry for its object
LEFT_OUT = {"runner-vehicle", "runner-shape-left-out", "runner-hull-overlap", "runner-mesh-refused", "runner-soft-body"}


def _kind(path: Path):
    try:
        doc, _ = read_file(path)
    except AdfError:
        return None
    return doc


def _corpus_scenes() -> tuple[list, list]:
    """(launch entries: (launch file, index), model files) of the corpus; empty without it."""
    if not CORPUS.is_dir():
        return [], []
    launches, models = [], []
    for p in sorted(CORPUS.rglob("*.yaml")):
        doc = _kind(p)
        if isinstance(doc, Launch):
            launches += [(p, i) for i in range(len(doc.multibody_configs or []))]
        elif isinstance(doc, ModelFile) and (doc.bodies or doc.soft_bodies or doc.volumes):
            models.append(p)
    return launches, models


LAUNCHES, MODELS = _corpus_scenes()
SCENES = [pytest.param((p, None), id=f"sample/{p.parent.name}") for p in SAMPLES]
SCENES += [pytest.param((p, i), id=f"{p.relative_to(CORPUS)}@{i}") for p, i in LAUNCHES]
SCENES += [pytest.param((p, None), id=str(p.relative_to(CORPUS)), marks=pytest.mark.slow) for p in MODELS]


def _run(argv: list[str]) -> tuple[int, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = main(argv)
    return rc, out.getvalue() + err.getvalue()


def _findings(text: str) -> list[re.Match]:
    return [m for line in text.splitlines() if (m := FINDING.match(line))]


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
@pytest.mark.parametrize("scene", SCENES)
def test_every_scene_plays_in_both_engines(scene, engine, tmp_path):
    path, index = scene
    argv = ["run", str(path), "--engine", engine, "--seconds", "0.02", "--no-frames", "--out", str(tmp_path)]
    if index is not None:
        argv[2:2] = ["-l", str(index)]
    rc, text = _run(argv)
    assert "Traceback" not in text
    assert not [ln for ln in text.splitlines() if UNLOCATED.match(ln)], text  # every finding says where
    if rc == 2:  # a scene AMBF rejects too: located errors, no report
        assert any(m["sev"] == "error" and m["where"] for m in _findings(text)), text
        return
    assert rc in (0, 1), text  # 1: an instability the report names (a body flung, ...)
    report = json.loads((tmp_path / "report.json").read_text(), parse_constant=lambda c: pytest.fail(c))
    assert report["engine"] == engine and report["steps"] == 20
    left_out = {entry["object"] for entry in report["not_played"]}
    for m in _findings(text):
        if m["rule"] in LEFT_OUT:
            assert m["msg"].split(":", 1)[0] in left_out, (m.group(0), report["not_played"])


def _models_of(path: Path, indices=None) -> list[Path]:
    """The model files a scene loads (a launch file's entries ``indices``, all when None)."""
    doc = _kind(path)
    if isinstance(doc, ModelFile):
        return [path]
    if isinstance(doc, Launch):
        configs = doc.multibody_configs or []
        chosen = [configs[i] for i in indices] if indices is not None else configs
        return [(path.parent / c).resolve() for c in chosen if (path.parent / c).is_file()]
    return []


#: the challenge's scene (src/launch.yaml -l 6-11) converts by default, the other corpus models with -m slow
CHALLENGE = set(_models_of(CORPUS / "src" / "launch.yaml", range(6, 12))) if CORPUS.is_dir() else set()
CONVERTED = [
    pytest.param(m, id=f"sample/{m.relative_to(ROOT / 'sample_scenes')}") for p in SAMPLES for m in _models_of(p)
]
CONVERTED += [
    pytest.param(m, id=str(m.relative_to(CORPUS)), marks=() if m.resolve() in CHALLENGE else pytest.mark.slow)
    for m in MODELS
]


@pytest.mark.parametrize("model", CONVERTED)
def test_every_model_converts_to_urdf_and_mjcf_and_loads(model, tmp_path):
    import mujoco

    for fmt in ("urdf", "xml"):
        out = tmp_path / fmt / f"{model.stem}.{fmt}"
        rc, text = _run(["convert", str(model), str(out), "--json"])
        assert "Traceback" not in text
        if rc == 2:  # what AMBF rejects (the corpus's urdf-*.yaml) is a located error
            assert any(m["sev"] == "error" and m["where"] for m in _findings(text)), text
            return
        assert rc == 0 and out.is_file(), text
        if fmt == "xml":
            mujoco.MjModel.from_xml_path(str(out))  # raises on anything MuJoCo cannot load
        else:
            cid = pb.connect(pb.DIRECT)
            try:
                uid = pb.loadURDF(str(out), physicsClientId=cid, flags=pb.URDF_USE_INERTIA_FROM_FILE)
                assert uid >= 0
            finally:
                pb.disconnect(cid)
