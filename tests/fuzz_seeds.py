"""Seeds for the fuzz suite (tests/fuzzkit.py): small hand-written scenes, the bundled sample
scene and, when present, the corpus."""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

SMALL_MODEL = """bodies: [BODY base, BODY link, BODY part]
joints: [JOINT hinge]
sensors: [SENSOR prox]
BODY base:
  name: base
  mass: 0.0
  location: {position: {x: 0.0, y: 0.0, z: 0.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  collision shape: BOX
  collision geometry: {x: 0.2, y: 0.2, z: 0.05}
  shape: BOX
  geometry: {x: 0.2, y: 0.2, z: 0.05}
BODY link:
  name: link
  mass: 0.5
  inertia: {ix: 0.001, iy: 0.001, iz: 0.001}
  location: {position: {x: 0.0, y: 0.0, z: 0.1}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  collision shape: CYLINDER
  collision geometry: {radius: 0.02, height: 0.1, axis: z}
  shape: CYLINDER
  geometry: {radius: 0.02, height: 0.1, axis: z}
  color rgba: {r: 0.5, g: 0.5, b: 0.9, a: 1.0}
BODY part:
  name: part
  mass: 0.1
  inertia: {ix: 0.0001, iy: 0.0001, iz: 0.0001}
  location: {position: {x: 0.3, y: 0.0, z: 0.1}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  mesh: part.stl
  scale: 1.0
JOINT hinge:
  name: hinge
  parent: BODY base
  child: BODY link
  type: revolute
  parent pivot: {x: 0.0, y: 0.0, z: 0.05}
  child pivot: {x: 0.0, y: 0.0, z: -0.05}
  parent axis: {x: 0.0, y: 0.0, z: 1.0}
  child axis: {x: 0.0, y: 0.0, z: 1.0}
  joint limits: {low: -1.0, high: 1.0}
  joint offset: 0.0
  max motor impulse: 0.05
SENSOR prox:
  name: prox
  type: Proximity
  parent: BODY link
  range: 0.1
  array: [{offset: {x: 0.0, y: 0.0, z: 0.0}, direction: {x: 1.0, y: 0.0, z: 0.0}}]
"""

SMALL_STL = """solid part
facet normal 0 0 -1
 outer loop
  vertex 0 0 0
  vertex 0.05 0 0
  vertex 0 0.05 0
 endloop
endfacet
facet normal 0 -1 0
 outer loop
  vertex 0 0 0
  vertex 0 0 0.05
  vertex 0.05 0 0
 endloop
endfacet
facet normal -1 0 0
 outer loop
  vertex 0 0 0
  vertex 0 0.05 0
  vertex 0 0 0.05
 endloop
endfacet
facet normal 1 1 1
 outer loop
  vertex 0.05 0 0
  vertex 0 0 0.05
  vertex 0 0.05 0
 endloop
endfacet
endsolid part
"""

SMALL_LAUNCH = """world config: world.yaml
color config: colors.yaml
input devices config: devices.yaml
multibody configs:
  - model.yaml
  - model2.yaml
"""

SMALL_WORLD = """environment: floor.yaml
gravity: {x: 0.0, y: 0.0, z: -9.8}
lights: [light1]
cameras: [cam]
light1:
  name: light1
  location: {x: 0.0, y: 0.0, z: 2.0}
  direction: {x: 0.0, y: 0.0, z: -1.0}
  shadow quality: 1
cam:
  name: cam
  location: {x: 1.0, y: 0.0, z: 0.5}
  look at: {x: 0.0, y: 0.0, z: 0.0}
  up: {x: 0.0, y: 0.0, z: 1.0}
  clipping plane: {near: 0.01, far: 10.0}
  field view angle: 0.8
"""

SMALL_FLOOR = """bodies: [BODY floor]
BODY floor:
  name: floor
  mass: 0.0
  location: {position: {x: 0.0, y: 0.0, z: -0.1}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  collision shape: BOX
  collision geometry: {x: 2.0, y: 2.0, z: 0.02}
  shape: BOX
  geometry: {x: 2.0, y: 2.0, z: 0.02}
"""

SMALL_DEVICES = """input devices: [dev]
dev:
  hardware name: MTMR
  haptic gain: {linear: 0.03, angular: 1.0}
  simulated multibody: model2.yaml
  root link: BODY ball
"""

SMALL_MODEL2 = """bodies: [BODY ball]
BODY ball:
  name: ball
  mass: 0.2
  inertia: {ix: 0.0001, iy: 0.0001, iz: 0.0001}
  location: {position: {x: 0.0, y: 0.3, z: 0.3}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  collision shape: SPHERE
  collision geometry: {radius: 0.03}
  shape: SPHERE
  geometry: {radius: 0.03}
"""

SMALL_URDF = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base">
    <inertial><mass value="1.0"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.05"/></geometry></collision>
  </link>
  <link name="link">
    <inertial><origin xyz="0 0 0.05"/><mass value="0.5"/>
      <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><mesh filename="part.stl" scale="1 1 1"/></geometry></visual>
    <collision><geometry><cylinder radius="0.02" length="0.1"/></geometry></collision>
  </link>
  <joint name="hinge" type="revolute">
    <parent link="base"/><child link="link"/>
    <origin xyz="0 0 0.05" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/>
  </joint>
</robot>
"""

SMALL_MJCF = """<mujoco model="arm">
  <compiler angle="radian"/>
  <asset><mesh name="part" file="part.stl"/></asset>
  <worldbody>
    <body name="base" pos="0 0 0">
      <geom type="box" size="0.1 0.1 0.025" mass="1"/>
      <body name="link" pos="0 0 0.1">
        <joint name="hinge" type="hinge" axis="0 0 1" range="-1 1"/>
        <geom type="cylinder" size="0.02 0.05" mass="0.5"/>
        <geom type="mesh" mesh="part" mass="0.1"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


@dataclass
class Seed:
    name: str
    files: dict[str, bytes]  # path in the scene folder -> content
    main: str  # the file commands are given
    kind: str  # "model", "launch", "urdf", "mjcf"
    small: bool = True  # cheap enough to play and convert


def builtin_seeds() -> list[Seed]:
    model = {"model.yaml": SMALL_MODEL.encode(), "part.stl": SMALL_STL.encode()}
    launch = {
        "launch.yaml": SMALL_LAUNCH.encode(),
        "world.yaml": SMALL_WORLD.encode(),
        "floor.yaml": SMALL_FLOOR.encode(),
        "devices.yaml": SMALL_DEVICES.encode(),
        "colors.yaml": b"red: {r: 1.0, g: 0.0, b: 0.0, a: 1.0}\n",
        **model,
        "model2.yaml": SMALL_MODEL2.encode(),
    }
    return [
        Seed("small-model", model, "model.yaml", "model"),
        Seed("small-launch", launch, "launch.yaml", "launch"),
        Seed("small-urdf", {"arm.urdf": SMALL_URDF.encode(), "part.stl": SMALL_STL.encode()}, "arm.urdf", "urdf"),
        Seed("small-mjcf", {"arm.xml": SMALL_MJCF.encode(), "part.stl": SMALL_STL.encode()}, "arm.xml", "mjcf"),
    ]


def sample_scene_seeds() -> list[Seed]:
    folder = ROOT / "sample_scenes" / "suturing_pad"
    if not folder.is_dir():
        return []
    files = {p.name: p.read_bytes() for p in folder.glob("*.yaml")}
    return [
        Seed("suturing-launch", files, "launch.yaml", "launch", small=False),
        Seed("suturing-pad", files, "pad.yaml", "model", small=False),
    ]


def corpus_seeds(corpus: Path, limit: int | None = None) -> list[Seed]:
    """Each corpus YAML file as a model/launch seed (alone in its folder: its meshes missing)."""
    if not corpus.is_dir():
        return []
    out = []
    for p in sorted(corpus.rglob("*.yaml")):
        data = p.read_bytes()
        kind = "launch" if re.search(rb"^(world config|multibody configs)\s*:", data, re.M) else "model"
        out.append(Seed(f"corpus:{p.relative_to(corpus)}", {p.name: data}, p.name, kind, small=len(data) < 20_000))
        if limit and len(out) >= limit:
            break
    return out
