"""Scenes at the edge of what an engine can load: a located error, never a traceback."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("mujoco", reason="mujoco (sim extra) is not installed")

from adfkit.cli import main  # noqa: E402


def _chain(n: int) -> str:
    """ADF text of ``n`` boxes in a line, each hinged to the one before."""
    out = ["bodies:"] + [f"- BODY L{i}" for i in range(n)] + ["joints:"] + [f"- JOINT J{i}" for i in range(1, n)]
    for i in range(n):
        out += [
            f"BODY L{i}:",
            f"  name: L{i}",
            f"  mass: {0.0 if i == 0 else 0.01}",
            "  inertia: {ix: 1.0e-6, iy: 1.0e-6, iz: 1.0e-6}",
            "  collision shape: Box",
            "  collision geometry: {x: 0.02, y: 0.01, z: 0.01}",
            f"  location: {{position: {{x: {0.02 * i:.3f}, y: 0.0, z: 1.0}}, orientation: {{r: 0, p: 0, y: 0}}}}",
        ]
    for i in range(1, n):
        out += [
            f"JOINT J{i}:",
            f"  name: J{i}",
            f"  parent: BODY L{i - 1}",
            f"  child: BODY L{i}",
            "  type: revolute",
            "  parent pivot: {x: 0.01, y: 0, z: 0}",
            "  child pivot: {x: -0.01, y: 0, z: 0}",
            "  parent axis: {x: 0, y: 1, z: 0}",
            "  child axis: {x: 0, y: 1, z: 0}",
        ]
    return "\n".join(out) + "\n"


def test_a_chain_deeper_than_mujocos_parser_allows_is_a_located_error(tmp_path, capsys):
    f = tmp_path / "chain.yaml"
    f.write_text(_chain(600))
    status = main(["run", str(f), "--engine", "mujoco", "--seconds", "0.01", "--no-frames"])
    err = capsys.readouterr().err
    assert status == 2, err
    assert f"{f}:" in err and "error[mujoco-tree-too-deep]" in err and "--engine pybullet" in err
    assert "Traceback" not in err


def test_a_chain_within_the_limit_plays_in_mujoco(tmp_path, capsys):
    f = tmp_path / "chain.yaml"
    f.write_text(_chain(120))
    assert main(["run", str(f), "--engine", "mujoco", "--seconds", "0.01", "--no-frames"]) == 0, capsys.readouterr().err


def test_constraint_algebra_follows_the_inertia_matrix(tmp_path):
    """Dense for a serial chain (every dof coupled), sparse for many free bodies joined by p2p
    and for the suturing scene, whose thread's chain fills most of the matrix but not all (the
    four-pair suture plays 1.38x faster sparse, the chain on the ground 2.4x faster dense)."""
    import mujoco

    from adfkit.adf import load_scene
    from adfkit.runner import Options
    from adfkit.runner.mujoco.world import MujocoWorld

    hinged = tmp_path / "hinged.yaml"
    hinged.write_text(_chain(80))
    p2p = tmp_path / "p2p.yaml"
    p2p.write_text(_chain(80).replace("type: revolute", "type: p2p"))
    worlds = [MujocoWorld(load_scene(f), Options(ground=False)) for f in (hinged, p2p)]
    try:
        assert [w.model.opt.jacobian for w in worlds] == [
            mujoco.mjtJacobian.mjJAC_DENSE,
            mujoco.mjtJacobian.mjJAC_SPARSE,
        ]
        assert worlds[1].model.nv == 6 * 79  # free bodies: the matrix is block-diagonal
        suturing = Path(__file__).resolve().parent.parent / "sample_scenes" / "suturing" / "launch.yaml"
        worlds.append(MujocoWorld(load_scene(suturing), Options()))
        m = worlds[-1].model
        assert 0.7 < m.nM / (m.nv * (m.nv + 1) / 2) < 0.9  # the thread's chain and the arms
        assert m.opt.jacobian == mujoco.mjtJacobian.mjJAC_SPARSE
    finally:
        for w in worlds:
            w.close()
