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
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SECRET = "ADFKIT-CANARY-7f3a9c"
PASSWD_MARK = "root:x:0:0"
LOCATED = re.compile(r"^(?P<file>[^\n]+?)(?::(?P<line>\d+):(?P<col>\d+))?: error\[(?P<rule>[a-z0-9-]+)\]: ", re.M)

# ---------------------------------------------------------------------------------------------
# Seeds

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
    main: str                # the file commands are given
    kind: str                # "model", "launch", "urdf", "mjcf"
    small: bool = True       # cheap enough to play and convert


def builtin_seeds() -> list[Seed]:
    model = {"model.yaml": SMALL_MODEL.encode(), "part.stl": SMALL_STL.encode()}
    launch = {"launch.yaml": SMALL_LAUNCH.encode(), "world.yaml": SMALL_WORLD.encode(),
              "floor.yaml": SMALL_FLOOR.encode(), "devices.yaml": SMALL_DEVICES.encode(),
              "colors.yaml": b"red: {r: 1.0, g: 0.0, b: 0.0, a: 1.0}\n", **model,
              "model2.yaml": SMALL_MODEL2.encode()}
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
    return [Seed("suturing-launch", files, "launch.yaml", "launch", small=False),
            Seed("suturing-pad", files, "pad.yaml", "model", small=False)]


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


# ---------------------------------------------------------------------------------------------
# Operators: each takes (rng, files, seed) and returns (files, extra) where extra may plant
# symlinks, FIFOs and folders: {"symlinks": {name: target}, "fifos": [name], "dirs": [name]}.

HOSTILE_PATHS = [
    "/etc/passwd", "../../../../../../../../etc/passwd", "/dev/zero", "/dev/stdin", "/proc/self/environ",
    "{outside}/secret.yaml", "{outside}/secret.stl", "link_out.yaml", "link_out.stl", "fifo.yaml", "folder",
    "x" * 300 + ".stl", ("d" * 200 + "/") * 25 + "m.stl", "a\\0b.stl", "a\\nb.stl", "é/ü.stl", "\\x1b[2J.stl",
    "C:\\\\meshes\\\\m.stl", "", " ", "~", "-", "part.STL", "./../part.stl",
]
ODD_VALUES = ["[1, 2]", "{a: 1}", "'text'", "true", "~", "''", "-1", "0", "1e-320", "[]", "{}", "[[], {}]",
              "\"\\u0000\"", "*nope", "&a 1", "? x", "- x", "|\n    block", ">-\n    folded"]
NONFINITE = [".inf", "-.inf", ".nan", ".NaN", "1e308", "-1e308", "1e400", "-1e400", "9" * 400, "-" + "1" * 5000,
             "0x7fffffffffffffffffff", "1_000_000_000_000_000_000_000", "4.9e-324", "1e-400"]
TAGGED = ["!!bool maybe", "!!int x", "!!float y", "!!timestamp z", '!!binary "@@"', "!!set {a, b}",
          "!!omap [a: 1]", "!custom v", "!!python/object:os.system ls", "!!str 1", "!!null x", "!!int 99999999999999999999999",
          "!!float .inf", "!<tag:yaml.org,2002:int> 3.5", "!!map [1]", "!!seq {a: 1}"]
ODD_BYTES = [b"\x00", b"\xff", b"\xef\xbb\xbf", b"\r", b"\t", b"\x1b[31m", b"\xc3", b"\xe2\x80\xa8", b"\xc2\x85",
             b"\xfe\xff", b"\x7f", b"\xf0\x9f\x98\x80", b"\r\n", b"\x0c", b"'", b'"', b"{", b"]", b": ", b"- ", b"#",
             b"&", b"*", b"!", b"%YAML 1.1\n---\n", b"\n---\n", b"\n...\n"]
KEY_LINE = re.compile(rb"^(?P<indent> *)(?P<key>[^\s#:][^:\n]*?):(?P<sep> +)(?P<value>[^\n]+)$", re.M)
NUMBER = re.compile(rb"(?<=[\s{,:\[])-?\d+\.?\d*(?:e-?\d+)?(?=[\s,}\]]|$)", re.M)
PATH_KEYS = (b"mesh", b"collision mesh", b"world config", b"environment", b"input devices config", b"color config",
             b"simulated multibody", b"high resolution path", b"low resolution path", b"path", b"filename")


def _yaml_files(files: dict[str, bytes], seed: Seed) -> list[str]:
    return [k for k in files if k.endswith((".yaml", ".yml"))] or [seed.main]


def _pick_file(rng, files, seed) -> str:
    names = _yaml_files(files, seed)
    return seed.main if seed.main in names and rng.random() < 0.6 else rng.choice(names)


def _key_lines(data: bytes) -> list[re.Match]:
    return list(KEY_LINE.finditer(data))


def _replace_value(rng, data: bytes, values: list[str], keys: tuple[bytes, ...] | None = None) -> bytes:
    lines = [m for m in _key_lines(data) if keys is None or m.group("key").strip() in keys]
    if not lines:
        return data + b"\nextra: " + rng.choice(values).encode() + b"\n"
    m = rng.choice(lines)
    return data[: m.start("value")] + rng.choice(values).encode("utf-8", "surrogateescape") + data[m.end("value"):]


def op_type_swap(rng, files, seed):
    f = _pick_file(rng, files, seed)
    files[f] = _replace_value(rng, files[f], ODD_VALUES)
    return files, {}


def op_delete(rng, files, seed):
    f = _pick_file(rng, files, seed)
    lines = files[f].split(b"\n")
    if len(lines) > 1:
        i = rng.randrange(len(lines))
        n = 1 if rng.random() < 0.7 else rng.randint(2, 8)
        del lines[i:i + n]
    files[f] = b"\n".join(lines)
    if rng.random() < 0.15:  # a whole file gone
        victim = rng.choice(list(files))
        if victim != seed.main:
            del files[victim]
    return files, {}


def op_dangle(rng, files, seed):
    f = _pick_file(rng, files, seed)
    files[f] = _replace_value(rng, files[f], ["BODY nowhere", "BODY base", "nope.yaml", "BODY ", "BODY link/x",
                                              "/ambf/env/BODY link", "BODY Entry", "BODY Thread_01"],
                              (b"parent", b"child", b"world config", b"environment", b"root link", b"chassis",
                               b"simulated multibody"))
    return files, {}


def op_nonfinite(rng, files, seed):
    f = _pick_file(rng, files, seed)
    data = files[f]
    hits = list(NUMBER.finditer(data))
    for _ in range(rng.randint(1, 3)):
        if not hits:
            break
        m = rng.choice(hits)
        data = data[: m.start()] + rng.choice(NONFINITE).encode() + data[m.end():]
        hits = list(NUMBER.finditer(data))
    files[f] = data
    return files, {}


def op_deep(rng, files, seed):
    f = _pick_file(rng, files, seed)
    n = rng.choice([5, 99, 100, 101, 1000, 5000, 200_000])
    style = rng.choice(["flow-seq", "flow-map", "block", "dashes"])
    if style == "flow-seq":
        value = "[" * n + "]" * n
    elif style == "flow-map":
        value = "{a: " * n + "1" + "}" * n
    elif style == "dashes":
        value = "\n  " + "- " * n + "x"
    else:
        n = min(n, 3000)
        value = "\n" + "".join("  " * (i + 1) + f"k{i}:\n" for i in range(n)) + "  " * (n + 1) + "v"
    files[f] = _replace_value(rng, files[f], [value])
    return files, {}


def op_alias(rng, files, seed):
    f = _pick_file(rng, files, seed)
    kind = rng.choice(["bomb", "recursive", "undefined", "shared", "merge"])
    if kind == "bomb":
        levels = rng.randint(5, 9)
        block = "lol0: &l0 [x, x, x, x, x, x, x, x, x, x]\n" + "".join(
            f"lol{i}: &l{i} [{', '.join([f'*l{i - 1}'] * 10)}]\n" for i in range(1, levels))
        files[f] = files[f] + b"\n" + block.encode()
        if rng.random() < 0.5:
            files[f] = _replace_value(rng, files[f], [f"*l{levels - 1}"])
    elif kind == "recursive":
        files[f] = files[f] + b"\nloop: &r [a, *r]\n"
    elif kind == "undefined":
        files[f] = _replace_value(rng, files[f], ["*missing"])
    elif kind == "shared":
        files[f] = b"shared: &s {x: 1.0, y: 2.0, z: 3.0}\n" + _replace_value(rng, files[f], ["*s"])
    else:
        files[f] = b"base: &b {mass: 1.0}\n" + _replace_value(rng, files[f], ["{<<: *b, name: m}"])
    return files, {}


def op_tag(rng, files, seed):
    f = _pick_file(rng, files, seed)
    files[f] = _replace_value(rng, files[f], TAGGED)
    return files, {}


def op_odd_bytes(rng, files, seed):
    f = rng.choice(list(files))
    data = bytearray(files[f])
    for _ in range(rng.randint(1, 4)):
        pos = rng.randrange(len(data) + 1)
        if rng.random() < 0.3 and data:
            data[pos % len(data)] = rng.randrange(256)
        else:
            data[pos:pos] = rng.choice(ODD_BYTES)
    if rng.random() < 0.1:
        data = data[: rng.randrange(len(data) + 1)]  # truncated
    files[f] = bytes(data)
    return files, {}


def op_path(rng, files, seed):
    f = _pick_file(rng, files, seed)
    target = rng.choice(HOSTILE_PATHS)
    quoted = '"' + target.replace('"', '\\"') + '"'
    files[f] = _replace_value(rng, files[f], [quoted], PATH_KEYS)
    if rng.random() < 0.3 and seed.kind == "launch":
        files[f] = files[f].replace(b"  - model2.yaml", b"  - " + quoted.encode())
    return files, _plants()


def _plants() -> dict:
    return {"symlinks": {"link_out.yaml": "{outside}/secret.yaml", "link_out.stl": "{outside}/secret.stl",
                         "link_passwd.yaml": "/etc/passwd"},
            "fifos": ["fifo.yaml"], "dirs": ["folder"]}


def op_keys(rng, files, seed):
    f = _pick_file(rng, files, seed)
    data = files[f]
    lines = _key_lines(data)
    insert = rng.choice(["1: x", "~: y", "? [a, b]\n{i}: c", "null: 1", "true: yes", "1.5: z", "[a]: 1",
                         "{a: 1}: 2", "'': empty", "controller: {kDP, 0.001}", "<<: {mass: 2.0}"])
    if lines:
        m = rng.choice(lines)
        indent = m.group("indent").decode()
        text = indent + insert.replace("\n{i}", "\n" + indent) + "\n"
        data = data[: m.start()] + text.encode() + data[m.start():]
    else:
        data = insert.encode() + b"\n" + data
    files[f] = data
    return files, {}


def op_duplicate(rng, files, seed):
    f = _pick_file(rng, files, seed)
    data = files[f]
    lines = _key_lines(data)
    if lines:
        m = rng.choice(lines)
        dup = data[m.start():m.end()] + b"\n"
        if rng.random() < 0.5:
            dup = data[m.start():m.start("value")] + rng.choice(ODD_VALUES).encode() + b"\n"
        data = data[: m.start()] + dup + data[m.start():]
    files[f] = data
    return files, {}


def op_garbage_mesh(rng, files, seed):
    kind = rng.choice(["random", "empty", "points", "nan", "huge-count", "binary-lie", "ascii-junk", "zero-area"])
    if kind == "random":
        data = bytes(rng.randrange(256) for _ in range(rng.randint(1, 600)))
    elif kind == "empty":
        data = b""
    elif kind == "points":
        data = b"solid p\nendsolid p\n"
    elif kind == "nan":
        data = SMALL_STL.replace("0.05", "nan", 2).encode()
    elif kind == "huge-count":  # binary STL header claiming 2^31 triangles
        data = b"\0" * 80 + (2**31 - 1).to_bytes(4, "little") + b"\0" * 50
    elif kind == "binary-lie":
        data = b"\0" * 80 + (3).to_bytes(4, "little") + b"\x01" * 20
    elif kind == "zero-area":
        data = SMALL_STL.replace("0.05", "0").encode()
    else:
        data = b"solid\nfacet normal a b c\nouter loop\nvertex 1 2\nendloop\nendfacet\nendsolid\n"
    files["part.stl"] = data
    f = _pick_file(rng, files, seed)
    if seed.kind in ("model", "launch") and b"part.stl" not in files[f] and rng.random() < 0.5:
        files[f] = _replace_value(rng, files[f], ["part.stl"], (b"mesh", b"collision mesh"))
    return files, {}


XML_ATTRS = ['velocity="abc"', 'effort="nan"', 'xyz="1 2"', 'rpy="inf 0 0"', 'value="-1"', 'size="0 0 0"',
             'radius="1e400"', 'lower="1" upper="-1"', 'filename="/etc/passwd"', 'file="/dev/zero"',
             'filename="{outside}/secret.stl"', 'file="../../../../etc/passwd"', 'name=""', 'type="ball"',
             'axis="0 0 0"', 'scale="1e308 1 1"', 'pos="nan nan nan"', 'mass="1e308"']
XML_BLOCKS = [
    '<!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">]>',
    '<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]>',
    '<!DOCTYPE r SYSTEM "http://example.invalid/x.dtd">',
    '<include file="/etc/passwd"/>', '<include file="{outside}/secret.xml"/>', '<include file="link_out.xml"/>',
    '<include file="fifo.yaml"/>', '<xi:include xmlns:xi="http://www.w3.org/2001/XInclude" href="/etc/passwd"/>',
    "<?xml-stylesheet href='/etc/passwd'?>", "<![CDATA[ ]]>", "&x;", "<a>" * 5000 + "</a>" * 5000, "<unclosed>",
]


def op_xml(rng, files, seed):
    f = seed.main
    data = files[f].decode("utf-8", "replace")
    kind = rng.random()
    if kind < 0.35:
        attrs = list(re.finditer(r'(\w+)="[^"]*"', data))
        if attrs:
            m = rng.choice(attrs)
            data = data[: m.start()] + rng.choice(XML_ATTRS) + data[m.end():]
    elif kind < 0.7:
        block = rng.choice(XML_BLOCKS)
        if block.startswith("<!DOCTYPE") or block.startswith("<?xml-"):
            data = data.replace('<?xml version="1.0"?>\n', "")
            data = block + "\n" + data
        else:
            tags = [m.end() for m in re.finditer(r"<(robot|mujoco|worldbody|link|body)\b[^>]*>", data)]
            pos = rng.choice(tags) if tags else len(data)
            data = data[:pos] + block + data[pos:]
    elif kind < 0.85:
        elems = list(re.finditer(r"<(\w+)[^>]*/>", data))
        if elems:
            m = rng.choice(elems)
            data = data[: m.start()] + data[m.end():]
    else:
        data = data[: rng.randrange(len(data) + 1)]
    files[f] = data.encode("utf-8", "surrogateescape")
    return files, _plants()


YAML_OPS = {"type_swap": op_type_swap, "delete": op_delete, "dangle": op_dangle, "nonfinite": op_nonfinite,
            "deep": op_deep, "alias": op_alias, "tag": op_tag, "odd_bytes": op_odd_bytes, "path": op_path,
            "keys": op_keys, "duplicate": op_duplicate, "garbage_mesh": op_garbage_mesh}
XML_OPS = {"xml": op_xml, "xml2": op_xml, "odd_bytes": op_odd_bytes, "garbage_mesh": op_garbage_mesh}


# ---------------------------------------------------------------------------------------------
# Cases


@dataclass
class Case:
    seed: str
    index: int
    op: str
    command: str
    files: dict[str, bytes]
    argv: list[str]              # "{dir}" and "{outside}" are filled in by run_case
    plants: dict = field(default_factory=dict)
    explicit: bool = False       # the hostile file is named on the command line itself

    @property
    def id(self) -> str:
        return f"{self.seed}#{self.index}:{self.op}:{self.command}"


def commands_for(seed: Seed, with_run: bool, with_blender: bool) -> list[tuple[str, list[str]]]:
    main = "{dir}/" + seed.main
    if seed.kind in ("urdf", "mjcf"):
        other = "mjcf" if seed.kind == "urdf" else "urdf"
        return [("convert-adf", ["convert", main, "{dir}/out.yaml", "--json"]),
                ("convert-" + other, ["convert", main, "{dir}/out." + ("xml" if other == "mjcf" else "urdf"), "--json"])]
    cmds = [("validate-text", ["validate", main]), ("validate-json", ["validate", "-f", "json", main]),
            ("validate-github", ["validate", "-f", "github", main]), ("validate-sarif", ["validate", "-f", "sarif", main]),
            ("info", ["info", main]), ("info-json", ["info", "--json", main])]
    if seed.kind == "launch":
        cmds += [("info-l", ["info", "-l", "0,1", main])]
    if seed.kind == "model" and seed.small:
        cmds += [("convert-urdf", ["convert", main, "{dir}/out.urdf", "--json"]),
                 ("convert-mjcf", ["convert", main, "{dir}/out.xml", "--json"]),
                 ("convert-adf", ["convert", main, "{dir}/out.yaml"])]
    if with_run and seed.small:
        extra = ["-l", "0,1"] if seed.kind == "launch" else []
        cmds += [("run", ["run", main, *extra, "--seconds", "0.004", "--no-frames", "--out", "{dir}/run"])]
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
    for i, target in enumerate(["/dev/zero", "/dev/stdin", "/dev/urandom", "{dir}/fifo.yaml", "{dir}/folder",
                                "{dir}/a\0b.yaml", "{dir}/" + "x" * 300 + ".yaml", "{dir}/nope.yaml",
                                "{dir}/link_out.yaml", "{dir}/" + "d/" * 3000 + "m.yaml"]):
        for cmd in (["validate"], ["validate", "-f", "json"], ["info"], ["info", "-l", "0"], ["run", "--seconds", "0.004"],
                    ["convert", "{target}", "{dir}/out.urdf"]):
            argv = [a.replace("{target}", target) for a in cmd] if "{target}" in cmd else [*cmd, target]
            out.append(Case("explicit", i, "named", " ".join(cmd[:2]).replace("{target}", "").strip(), {}, argv,
                            _plants(), explicit=True))
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
    error: str | None        # an exception that escaped main, or a timeout
    opened: list[str]
    scene: Path
    outside: Path


def materialise(case: Case, scene: Path, outside: Path) -> None:
    scene.mkdir(parents=True, exist_ok=True)
    outside.mkdir(parents=True, exist_ok=True)
    (outside / "secret.yaml").write_text(f"bodies: [BODY {SECRET}]\nBODY {SECRET}:\n  name: {SECRET}\n  mass: 1\n")
    (outside / "secret.stl").write_text(SMALL_STL.replace("solid part", f"solid {SECRET}"))
    (outside / "secret.xml").write_text(f'<mujoco model="{SECRET}"><worldbody><body name="{SECRET}"/></worldbody></mujoco>\n')
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
    case = Case(case.seed, case.index, case.op, case.command,
                {k: v.replace(b"{outside}", str(outside).encode()) for k, v in case.files.items()},
                case.argv, case.plants, case.explicit)
    materialise(case, scene, outside)
    argv = [_fill(a, scene, outside) for a in case.argv]
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
    return Outcome(case, rc, out.getvalue(), err.getvalue(), error, opened, scene, outside)


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


_FRAME = re.compile(r'File "[^"]*/(adfkit/[^"]+)", line \d+, in (\w+)')
_EXC = re.compile(r"^(\w+(?:Error|Exception|error))\b", re.M)


def crash_site(o: Outcome) -> tuple[str, str, str] | None:
    """(module, function, exception) of an exception that escaped: the innermost adfkit frame."""
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
