"""The project's own full suturing scene (``adfkit build-scene suturing DIR``): the world with
the stereo camera pair, lights and a floor; the tissue phantom with four entry/exit pairs, hole
ghosts and capsule boundaries; the curved needle with its CoACD collision; the 40-element
thread; two LND 400006 PSMs with finger ghosts, a constraint actuator and a proximity sensor
each. Every ADF file goes through the model and the ADF writer; meshes and textures are made
here (see layout.py for where things are and why)."""

from __future__ import annotations

from pathlib import Path

PSMS = ("psm1", "psm2")

#: files of a build, relative to its folder (the launch file last)
LAUNCH = "launch.yaml"


def _write_bytes(path: Path, data: bytes) -> None:
    import os

    from ...adf.writer import atomic_write_text
    from ...scratch import temp_beside

    if isinstance(data, str):
        atomic_write_text(path, data)
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = temp_beside(path)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_suturing(out_dir: str | Path) -> Path:
    """Write the scene into ``out_dir`` (created if needed); returns the launch file."""
    from ...adf.writer import write_file
    from ...model import Colors, InputDevices, Launch
    from . import layout, needle, phantom, psm, textures, world

    out = Path(out_dir)
    for sub in ("world/meshes", "psm/meshes", "phantom/meshes"):
        (out / sub).mkdir(parents=True, exist_ok=True)
    write_file(world.build_world(), out / "world" / "world.yaml")
    write_file(world.build_floor(), out / "world" / "floor.yaml")
    _write_bytes(out / "world" / "meshes" / "Floor.OBJ", world.floor_obj_text())
    _write_bytes(out / "world" / "meshes" / "Floor.mtl", world.floor_mtl_text())
    _write_bytes(out / "world" / "meshes" / "checker.png", world.checker_png())
    configs = []
    for file_name, text in psm.link_meshes().items():
        _write_bytes(out / "psm" / "meshes" / file_name, text)
    for name in PSMS:
        write_file(psm.build_psm(name, layout.psm_base(name), layout.q_home()), out / "psm" / f"{name}.yaml")
        write_file(psm.build_psm_ghosts(name), out / "psm" / f"ghosts_actuators_{name}.yaml")
        configs += [f"psm/{name}.yaml", f"psm/ghosts_actuators_{name}.yaml"]
    write_file(phantom.build_phantom(), out / "phantom" / "phantom.yaml")
    write_file(phantom.build_hole_ghosts(), out / "phantom" / "ghosts.yaml")
    configs += ["phantom/phantom.yaml", "phantom/ghosts.yaml"]
    meshes = out / "phantom" / "meshes"
    _write_bytes(meshes / "Phantom.OBJ", phantom.phantom_obj_text())
    _write_bytes(meshes / "Phantom.mtl", phantom.phantom_mtl_text())
    _write_bytes(meshes / "tissue.png", textures.tissue_png())
    _write_bytes(meshes / "tissue_normal.png", textures.normal_png())
    _write_bytes(meshes / "Needle.OBJ", needle.needle_obj_text())
    _write_bytes(meshes / "Needle.mtl", needle.needle_mtl_text())
    hulls_obj, hulls_mtl = needle.needle_hulls_text()
    _write_bytes(meshes / "NeedleCollision.OBJ", hulls_obj)
    _write_bytes(meshes / "NeedleCollision.mtl", hulls_mtl)
    write_file(InputDevices(present_lists={"input devices"}), out / "input_devices.yaml")
    from .needle import STEEL
    from .phantom import HOLE
    from .thread import COLOUR

    write_file(Colors(colors={"steel": STEEL, "thread": COLOUR, "hole": HOLE}), out / "colors.yaml")
    launch = Launch(
        world_config="world/world.yaml",
        color_config="colors.yaml",
        input_devices_config="input_devices.yaml",
        multibody_configs=configs,
    )
    return write_file(launch, out / LAUNCH)


__all__ = ["write_suturing", "PSMS"]
