"""Mutation operators for the fuzz suite (tests/fuzzkit.py). Each takes (rng, files, seed) and
returns (files, plants): plants may ask for symlinks, FIFOs and folders in the scene."""

from __future__ import annotations

import re

from fuzz_seeds import SMALL_STL, Seed

HOSTILE_PATHS = [
    "/etc/passwd",
    "../../../../../../../../etc/passwd",
    "/dev/zero",
    "/dev/stdin",
    "/proc/self/environ",
    "{outside}/secret.yaml",
    "{outside}/secret.stl",
    "link_out.yaml",
    "link_out.stl",
    "fifo.yaml",
    "folder",
    "x" * 300 + ".stl",
    ("d" * 200 + "/") * 25 + "m.stl",
    "a\\0b.stl",
    "a\\nb.stl",
    "é/ü.stl",
    "\\x1b[2J.stl",
    "C:\\\\meshes\\\\m.stl",
    "",
    " ",
    "~",
    "-",
    "part.STL",
    "./../part.stl",
]
ODD_VALUES = [
    "[1, 2]",
    "{a: 1}",
    "'text'",
    "true",
    "~",
    "''",
    "-1",
    "0",
    "1e-320",
    "[]",
    "{}",
    "[[], {}]",
    '"\\u0000"',
    "*nope",
    "&a 1",
    "? x",
    "- x",
    "|\n    block",
    ">-\n    folded",
]
NONFINITE = [
    ".inf",
    "-.inf",
    ".nan",
    ".NaN",
    "1e308",
    "-1e308",
    "1e400",
    "-1e400",
    "9" * 400,
    "-" + "1" * 5000,
    "0x7fffffffffffffffffff",
    "1_000_000_000_000_000_000_000",
    "4.9e-324",
    "1e-400",
]
TAGGED = [
    "!!bool maybe",
    "!!int x",
    "!!float y",
    "!!timestamp z",
    '!!binary "@@"',
    "!!set {a, b}",
    "!!omap [a: 1]",
    "!custom v",
    "!!python/object:os.system ls",
    "!!str 1",
    "!!null x",
    "!!int 99999999999999999999999",
    "!!float .inf",
    "!<tag:yaml.org,2002:int> 3.5",
    "!!map [1]",
    "!!seq {a: 1}",
]
ODD_BYTES = [
    b"\x00",
    b"\xff",
    b"\xef\xbb\xbf",
    b"\r",
    b"\t",
    b"\x1b[31m",
    b"\xc3",
    b"\xe2\x80\xa8",
    b"\xc2\x85",
    b"\xfe\xff",
    b"\x7f",
    b"\xf0\x9f\x98\x80",
    b"\r\n",
    b"\x0c",
    b"'",
    b'"',
    b"{",
    b"]",
    b": ",
    b"- ",
    b"#",
    b"&",
    b"*",
    b"!",
    b"%YAML 1.1\n---\n",
    b"\n---\n",
    b"\n...\n",
]
KEY_LINE = re.compile(rb"^(?P<indent> *)(?P<key>[^\s#:][^:\n]*?):(?P<sep> +)(?P<value>[^\n]+)$", re.M)
NUMBER = re.compile(rb"(?<=[\s{,:\[])-?\d+\.?\d*(?:e-?\d+)?(?=[\s,}\]]|$)", re.M)
PATH_KEYS = (
    b"mesh",
    b"collision mesh",
    b"world config",
    b"environment",
    b"input devices config",
    b"color config",
    b"simulated multibody",
    b"high resolution path",
    b"low resolution path",
    b"path",
    b"filename",
)


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
    return data[: m.start("value")] + rng.choice(values).encode("utf-8", "surrogateescape") + data[m.end("value") :]


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
        del lines[i : i + n]
    files[f] = b"\n".join(lines)
    if rng.random() < 0.15:  # a whole file gone
        victim = rng.choice(list(files))
        if victim != seed.main:
            del files[victim]
    return files, {}


def op_dangle(rng, files, seed):
    f = _pick_file(rng, files, seed)
    files[f] = _replace_value(
        rng,
        files[f],
        [
            "BODY nowhere",
            "BODY base",
            "nope.yaml",
            "BODY ",
            "BODY link/x",
            "/ambf/env/BODY link",
            "BODY Entry",
            "BODY Thread_01",
        ],
        (b"parent", b"child", b"world config", b"environment", b"root link", b"chassis", b"simulated multibody"),
    )
    return files, {}


def op_nonfinite(rng, files, seed):
    f = _pick_file(rng, files, seed)
    data = files[f]
    hits = list(NUMBER.finditer(data))
    for _ in range(rng.randint(1, 3)):
        if not hits:
            break
        m = rng.choice(hits)
        data = data[: m.start()] + rng.choice(NONFINITE).encode() + data[m.end() :]
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
            f"lol{i}: &l{i} [{', '.join([f'*l{i - 1}'] * 10)}]\n" for i in range(1, levels)
        )
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
    return {
        "symlinks": {
            "link_out.yaml": "{outside}/secret.yaml",
            "link_out.stl": "{outside}/secret.stl",
            "link_passwd.yaml": "/etc/passwd",
        },
        "fifos": ["fifo.yaml"],
        "dirs": ["folder"],
    }


def op_keys(rng, files, seed):
    f = _pick_file(rng, files, seed)
    data = files[f]
    lines = _key_lines(data)
    insert = rng.choice(
        [
            "1: x",
            "~: y",
            "? [a, b]\n{i}: c",
            "null: 1",
            "true: yes",
            "1.5: z",
            "[a]: 1",
            "{a: 1}: 2",
            "'': empty",
            "controller: {kDP, 0.001}",
            "<<: {mass: 2.0}",
        ]
    )
    if lines:
        m = rng.choice(lines)
        indent = m.group("indent").decode()
        text = indent + insert.replace("\n{i}", "\n" + indent) + "\n"
        data = data[: m.start()] + text.encode() + data[m.start() :]
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
        dup = data[m.start() : m.end()] + b"\n"
        if rng.random() < 0.5:
            dup = data[m.start() : m.start("value")] + rng.choice(ODD_VALUES).encode() + b"\n"
        data = data[: m.start()] + dup + data[m.start() :]
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


TRIANGLE_OBJ = b"v 0 0 0\nv 0.05 0 0\nv 0 0.05 0\nv 0 0 0.05\n"
#: what a static body's mesh may hold that no engine can make a shape of: (suffix, bytes)
BROKEN_MESHES = {
    "obj-face-past-vertices": (".obj", TRIANGLE_OBJ + b"f 1 2 3\nf 1 2 9\n"),
    "obj-face-zero": (".obj", TRIANGLE_OBJ + b"f 0 1 2\n"),
    "obj-face-relative-past": (".obj", TRIANGLE_OBJ + b"f -1 -2 -7\n"),
    "obj-face-word": (".obj", TRIANGLE_OBJ + b"f 1/1/1 2//2 x\n"),
    "obj-texture-index-past": (".obj", TRIANGLE_OBJ + b"vt 0 0\nf 1/1 2/9 3/1\n"),
    "obj-no-faces": (".obj", TRIANGLE_OBJ),
    "obj-no-vertices": (".obj", b"f 1 2 3\n"),
    "obj-empty": (".obj", b""),
    "obj-binary": (".obj", bytes(range(256)) * 3),
    "stl-empty": (".stl", b""),
    "stl-huge-count": (".stl", b"\0" * 80 + (2**31 - 1).to_bytes(4, "little") + b"\0" * 50),
    "stl-binary-lie": (".stl", b"\0" * 80 + (3).to_bytes(4, "little") + b"\x01" * 20),
    "stl-ascii-junk": (".stl", b"solid\nfacet normal a b c\nouter loop\nvertex 1 2\nendloop\nendfacet\nendsolid\n"),
    "3ds-empty": (".3ds", b""),
    "3ds-junk": (".3ds", b"\x4d\x4d" + (1000).to_bytes(4, "little") + bytes(range(200))),
}


def static_broken_mesh(files: dict[str, bytes], model: str, kind: str) -> dict[str, bytes]:
    """``files`` with one body of ``model`` that has a mesh made static (mass 0) and its mesh
    (and collision mesh) a broken file of ``kind`` (BROKEN_MESHES): every engine reads a static
    body's mesh as it is, without the mass properties that read a dynamic one first."""
    suffix, data = BROKEN_MESHES[kind]
    name = f"broken{suffix}"
    text = files[model].decode("utf-8", "surrogateescape")
    blocks = list(re.finditer(r"^(BODY [^\n:]+):\n((?:[ \t]+[^\n]*\n?)*)", text, re.M))
    meshed = [b for b in blocks if re.search(r"^[ \t]+(collision )?mesh:", b.group(2), re.M)]
    if not meshed:
        return files
    b = meshed[0]
    body = re.sub(r"^([ \t]+(?:collision )?mesh:)[^\n]*", rf"\1 {name}", b.group(2), flags=re.M)
    if re.search(r"^[ \t]+mass:", body, re.M):
        body = re.sub(r"^([ \t]+mass:)[^\n]*", r"\1 0.0", body, count=1, flags=re.M)
    else:
        body = "  mass: 0.0\n" + body
    text = text[: b.start(2)] + body + text[b.end(2) :]
    return {**files, model: text.encode("utf-8", "surrogateescape"), name: data}


def op_truncate(rng, files, seed):
    """A file cut short at a random byte (a copy or a download interrupted), in a multi-byte
    character, a quoted string or a flow collection as it falls."""
    f = _pick_file(rng, files, seed)
    files[f] = files[f][: rng.randrange(len(files[f]) + 1)]
    return files, {}


def op_static_broken_mesh(rng, files, seed):
    models = [f for f in _yaml_files(files, seed) if re.search(rb"^[ \t]+(collision )?mesh:", files[f], re.M)]
    if not models:
        return op_garbage_mesh(rng, files, seed)
    return static_broken_mesh(files, rng.choice(models), rng.choice(sorted(BROKEN_MESHES))), {}


XML_ATTRS = [
    'velocity="abc"',
    'effort="nan"',
    'xyz="1 2"',
    'rpy="inf 0 0"',
    'value="-1"',
    'size="0 0 0"',
    'radius="1e400"',
    'lower="1" upper="-1"',
    'filename="/etc/passwd"',
    'file="/dev/zero"',
    'filename="{outside}/secret.stl"',
    'file="../../../../etc/passwd"',
    'name=""',
    'type="ball"',
    'axis="0 0 0"',
    'scale="1e308 1 1"',
    'pos="nan nan nan"',
    'mass="1e308"',
]
XML_BLOCKS = [
    '<!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">]>',
    '<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]>',
    '<!DOCTYPE r SYSTEM "http://example.invalid/x.dtd">',
    '<include file="/etc/passwd"/>',
    '<include file="{outside}/secret.xml"/>',
    '<include file="link_out.xml"/>',
    '<include file="fifo.yaml"/>',
    '<xi:include xmlns:xi="http://www.w3.org/2001/XInclude" href="/etc/passwd"/>',
    "<?xml-stylesheet href='/etc/passwd'?>",
    "<![CDATA[ ]]>",
    "&x;",
    "<a>" * 5000 + "</a>" * 5000,
    "<unclosed>",
]


def op_xml(rng, files, seed):
    f = seed.main
    data = files[f].decode("utf-8", "replace")
    kind = rng.random()
    if kind < 0.35:
        attrs = list(re.finditer(r'(\w+)="[^"]*"', data))
        if attrs:
            m = rng.choice(attrs)
            data = data[: m.start()] + rng.choice(XML_ATTRS) + data[m.end() :]
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
            data = data[: m.start()] + data[m.end() :]
    else:
        data = data[: rng.randrange(len(data) + 1)]
    files[f] = data.encode("utf-8", "surrogateescape")
    return files, _plants()


YAML_OPS = {
    "type_swap": op_type_swap,
    "delete": op_delete,
    "dangle": op_dangle,
    "nonfinite": op_nonfinite,
    "deep": op_deep,
    "alias": op_alias,
    "tag": op_tag,
    "odd_bytes": op_odd_bytes,
    "path": op_path,
    "keys": op_keys,
    "duplicate": op_duplicate,
    "garbage_mesh": op_garbage_mesh,
    "static_broken_mesh": op_static_broken_mesh,
    "truncate": op_truncate,
}
XML_OPS = {"xml": op_xml, "xml2": op_xml, "odd_bytes": op_odd_bytes, "garbage_mesh": op_garbage_mesh}
