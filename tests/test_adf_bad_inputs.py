"""Issue 4: every user mistake gives the expected rule id at the right line:col, exit
status 2 from `adfkit info`, and no traceback."""
from __future__ import annotations

import subprocess
import sys

import pytest

from adfkit.cli import main

MODEL_HEAD = "bodies: [BODY a]\nBODY a:\n"

# (case id, file bytes, rule, line, column)
CASES = [
    ("not-yaml", b"bodies: [a\n", "yaml-syntax", 2, 1),
    ("tab-indent", b"bodies:\n\t- a\n", "yaml-syntax", 2, 1),
    ("bad-mapping", b"bodies: [a]\n  mass: 1\n x: 2\n", "yaml-syntax", 2, 3),
    ("duplicate-top-key", b"bodies: []\njoints: []\nbodies: []\n", "yaml-duplicate-key", 3, 1),
    ("duplicate-body-key", (MODEL_HEAD + "  mass: 1\n  mass: 2\n").encode(), "yaml-duplicate-key", 4, 3),
    ("invalid-utf8", b"bodies: []\nname: caf\xe9\n", "yaml-encoding", 2, 10),
    ("empty-file", b"", "empty-file", 1, 1),
    ("comment-only", b"# nothing here\n", "empty-file", 1, 1),
    ("top-level-list", b"- bodies\n- joints\n", "not-a-mapping", 1, 1),
    ("top-level-scalar", b"hello\n", "not-a-mapping", 1, 1),
    ("unknown-kind", b"foo: 1\nbar: 2\n", "unknown-kind", 1, 1),
    ("mass-not-number", (MODEL_HEAD + "  mass: heavy\n").encode(), "bad-type", 3, 9),
    ("mass-is-list", (MODEL_HEAD + "  mass: [1, 2]\n").encode(), "bad-type", 3, 9),
    ("bool-as-int", (MODEL_HEAD + "  passive: 1\n").encode(), "bad-bool", 3, 12),
    ("bool-word", (MODEL_HEAD + "  passive: maybe\n").encode(), "bad-bool", 3, 12),
    ("int-with-fraction", b"lights: [l]\nenvironment: e.yaml\nl:\n  shadow quality: 2.5\n", "bad-int", 4, 19),
    ("negative-uint", b"lights: [l]\nenvironment: e.yaml\nl:\n  shadow quality: -1\n", "bad-int", 4, 19),
    ("vec3-missing-z", (MODEL_HEAD + "  gravity: {x: 0, y: 0}\n").encode(), "missing-component", 3, 12),
    ("rpy-missing-y", (MODEL_HEAD + "  location:\n    orientation: {r: 0, p: 0}\n").encode(), "missing-component", 4, 18),
    ("vec3-not-mapping", (MODEL_HEAD + "  gravity: [0, 0, -9.8]\n").encode(), "bad-type", 3, 12),
    ("list-not-list", b"bodies: BODY a\nBODY a: {mass: 1}\n", "bad-type", 1, 9),
    ("list-entry-mapping", b"bodies:\n  - {mass: 1}\n", "bad-type", 2, 5),
    ("joint-axis-text", b"joints: [j]\nj:\n  type: revolute\n  parent axis: up\n", "bad-type", 4, 16),
    ("shape-list-not-list", (MODEL_HEAD + "  compound collision shape: {shape: Box}\n").encode(), "bad-type", 3, 29),
    ("recursive-alias", b"bodies: &a [*a]\n", "yaml-recursive-alias", 1, 9),
    ("alias-bomb", ("a: &a [x,x,x,x,x,x,x,x,x,x]\n" + "".join(
        f"{chr(98 + i)}: &{chr(98 + i)} [*{chr(97 + i)},*{chr(97 + i)},*{chr(97 + i)},*{chr(97 + i)},"
        f"*{chr(97 + i)},*{chr(97 + i)},*{chr(97 + i)},*{chr(97 + i)},*{chr(97 + i)},*{chr(97 + i)}]\n"
        for i in range(7)) + "bodies: []\n").encode(), "yaml-alias-bomb", 1, 1),
]


@pytest.mark.parametrize("case,data,rule,line,col", CASES, ids=[c[0] for c in CASES])
def test_bad_input_is_located(tmp_path, capsys, case, data, rule, line, col):
    f = tmp_path / f"{case}.yaml"
    f.write_bytes(data)
    status = main(["info", str(f)])
    err = capsys.readouterr().err
    assert status == 2
    assert "Traceback" not in err
    assert f"{f}:{line}:{col}: error[{rule}]" in err, err


def test_missing_file_and_directory(tmp_path, capsys):
    assert main(["info", str(tmp_path / "absent.yaml")]) == 2
    assert "error[file-not-found]" in capsys.readouterr().err
    assert main(["info", str(tmp_path)]) == 2
    assert "error[not-a-regular-file]" in capsys.readouterr().err


def test_wrong_kind_is_reported(tmp_path, capsys):
    f = tmp_path / "model.yaml"
    f.write_text("bodies: []\n")
    assert main(["info", str(f), "--kind", "world"]) == 2
    assert f"{f}:1:1: error[wrong-kind]: this looks like a model file, not a world file" in capsys.readouterr().err


def test_undefined_object_is_a_warning_not_an_error(tmp_path, capsys):
    f = tmp_path / "m.yaml"
    f.write_text("bodies: [BODY a, BODY b]\nBODY a: {mass: 1}\n")
    assert main(["info", str(f)]) == 0
    err = capsys.readouterr().err
    assert f"{f}:1:18: warning[undefined-object]" in err


def test_cli_process_exits_2_without_traceback(tmp_path):
    f = tmp_path / "bad.yaml"
    f.write_text("bodies: [a\n")
    proc = subprocess.run([sys.executable, "-m", "adfkit", "info", str(f)], capture_output=True, text=True)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert f"{f}:2:1: error[yaml-syntax]" in proc.stderr
    assert "hint:" in proc.stderr
