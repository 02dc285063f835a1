"""Every rule the validator can report: stable id, severity, what it means, an example.

Severity follows what AMBF 2.x does (adf-format.md §15): ERROR when AMBF rejects the file
or crashes (undefined behaviour), WARNING when it loads the file but drops or changes
something, INFO for style and portability.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..diagnostics import Severity

E, W, I = Severity.ERROR, Severity.WARNING, Severity.INFO


@dataclass(frozen=True)
class Rule:
    id: str
    severity: Severity
    summary: str
    example: str


_RULES = [
    # --- reader (adfkit.adf) -----------------------------------------------------------
    Rule("yaml-syntax", E, "Not YAML that yaml-cpp or PyYAML reads", "`a: [1, 2` (unclosed flow list)"),
    Rule(
        "pyyaml-unparseable",
        W,
        "yaml-cpp (AMBF) reads it, PyYAML does not; checked after re-indenting",
        "`key: &anchor` followed by `{` at column 1 (rover_info.yaml)",
    ),
    Rule(
        "yaml-duplicate-key",
        W,
        "A key appears twice; AMBF keeps the first value, PyYAML the last",
        "`collision margin` twice in one body (sb/cloth.yaml)",
    ),
    Rule("yaml-encoding", E, "The file is not UTF-8", "a Latin-1 byte 0xe9 in a name"),
    Rule("yaml-too-deep", E, "Collections nest more than 100 levels deep", "`a: [[[[...]]]]` 1,000 levels deep"),
    Rule(
        "yaml-key-type",
        W,
        "A mapping key is not text (a number, null, a list); yaml-cpp compares it as text",
        "`{kDP, 0.001}` makes `0.001` a key",
    ),
    Rule("yaml-bad-tag", E, "An explicit tag whose value it cannot construct", "`!!bool maybe`"),
    Rule("yaml-alias-bomb", E, "Aliases expand to millions of nodes", "the billion-laughs pattern"),
    Rule("yaml-recursive-alias", E, "An alias refers to a node containing it", "`a: &x [*x]`"),
    Rule("empty-file", E, "The file holds no YAML document", "a 0-byte file"),
    Rule("not-a-mapping", E, "The top level is not a mapping", "`- bodies` (a list)"),
    Rule("unknown-kind", E, "Cannot tell launch/world/model/input-devices/colors apart", "a file with only `name: x`"),
    Rule(
        "drill-labels",
        E,
        "A volume's labels.yaml (adfkit drill's tissues by slice value) is malformed",
        "`bone: [255, 150]` (low above high)",
    ),
    Rule(
        "wrong-kind",
        E,
        "The file does not match --kind or the slot it is loaded into",
        "a model file named in `world config`",
    ),
    Rule("bad-type", E, "A value has the wrong type", "`mass: heavy`"),
    Rule("bad-bool", E, "A boolean is not a yaml-cpp boolean word", "`passive: 1`"),
    Rule("bad-int", E, "An integer field holds a fraction or a negative uint", "`shadow quality: 2.5`"),
    Rule(
        "missing-component",
        E,
        "A vector, orientation or colour lacks a component",
        "`location: {position: {x: 0, y: 0}}`",
    ),
    Rule(
        "bad-pose",
        W,
        "A pose block has keys other than position/orientation; AMBF uses identity",
        "`location: {x: 1, y: 0, z: 0}`",
    ),
    Rule(
        "undefined-object",
        W,
        "A listed identifier has no mapping in the file, or an empty one (AMBF skips that object)",
        "`bodies: [BODY a]` without `BODY a:`",
    ),
    Rule(
        "unknown-key",
        I,
        "A key AMBF does not read (WARNING when it is a near miss of a real key)",
        "`colision mesh: a.stl` (did you mean `collision mesh`?)",
    ),
    Rule("file-not-found", E, "A path given on the command line does not exist", "`adfkit validate nope.yaml`"),
    # --- input policy (adfkit.inputs) -----------------------------------------------------
    Rule("file-unreadable", E, "A file cannot be read (permissions, I/O error)", "a file with mode 000"),
    Rule("bad-path", E, "A path holds a NUL byte or a name over 255 bytes", '`mesh: "a\\0b.stl"`'),
    Rule("not-a-regular-file", E, "A path names a folder, device, FIFO or socket", "`world config: /dev/zero`"),
    Rule(
        "outside-tree",
        E,
        "A file named by an ADF file lies outside the scene's folder tree (not read)",
        "`input devices config: /etc/passwd`",
    ),
    Rule("file-too-large", E, "A file is over the size cap for its kind (16 MiB for ADF)", "a 20 MB YAML file"),
    # --- schema ------------------------------------------------------------------------
    Rule(
        "schema-required", E, "A key AMBF requires is missing (the file is rejected)", "a joint without `parent axis`"
    ),
    Rule("schema-type", E, "A value AMBF cannot convert (the file is rejected)", "`restitution:` (null)"),
    # --- semantic ----------------------------------------------------------------------
    Rule("adf-version", E, "`adf version` is not exactly 1.0", "`adf version: 2.0`"),
    Rule(
        "enable-motor-without-feedback",
        E,
        "`enable motor` without `enable feedback`: AMBF reads the missing `enable feedback` and rejects the file",
        "`enable motor: 1` alone (urdf-*.yaml)",
    ),
    Rule("joint-type", W, "Unknown joint type; AMBF keeps the joint but creates no constraint", "`type: Revolute`"),
    Rule("joint-zero-axis", E, "A joint axis is the zero vector (NaN frames)", "`parent axis: {x: 0, y: 0, z: 0}`"),
    Rule("joint-same-body", W, "A joint's parent and child are the same body", "`parent: BODY a`, `child: BODY a`"),
    Rule(
        "joint-static-parent",
        W,
        "A joint (hinge, slider, spring, fixed, p2p) whose parent is static with no collision shape and no inertia: AMBF's joint holds nothing in place",
        "`parent: BODY post` where `BODY post` has `mass: 0`, no `collision shape`, no `inertia`",
    ),
    Rule(
        "joint-limits",
        W,
        "Limits incomplete, low > high, or missing the six-dof / cone-twist structure",
        "`joint limits: {low: 1, high: -1}`",
    ),
    Rule(
        "joint-pose",
        W,
        "The bodies' `location`s put a revolute/prismatic joint outside its limits, or "
        "the child off the joint, or a fixed, p2p, cone-twist or torsion-spring joint's pivots apart "
        "(a revolute joint's too, to a body of an earlier file; AMBF moves it on the first steps)",
        "a child body 5 cm from its parent's pivot",
    ),
    Rule(
        "inertial-frame-turns-joint",
        W,
        "A jointed body's `inertial offset` is turned: AMBF builds the joint's frames in the inertial "
        "frames, which turns the joint's zero (a fixed or prismatic joint: its child) about its axis",
        "`inertial offset: {orientation: {y: 1.57}}` on a link of a revolute joint",
    ),
    Rule(
        "spring-without-limits", W, "A spring joint without limits stays locked", "`type: linear spring` and no limits"
    ),
    Rule(
        "dangling-reference",
        W,
        "A parent/child/chassis/root link names no body (AMBF skips the object)",
        "`child: BODY nonexistent`",
    ),
    Rule(
        "ambiguous-reference",
        W,
        "A reference matches several bodies by substring (AMBF fails)",
        "`parent: Entry1` with `BODY Entry1` and `BODY Entry10`",
    ),
    Rule(
        "external-reference",
        I,
        "A reference is not in this file; AMBF looks in models loaded earlier",
        "`parent: BODY world` defined in another model",
    ),
    Rule("missing-file", E, "A launch/world file names a file that does not exist", "`world config: ./nope.yaml`"),
    Rule(
        "missing-color-file",
        W,
        "A launch file's `color config` does not exist (AMBF 2.0 never opens it)",
        "`color config: colors.yaml` that is not there",
    ),
    Rule(
        "missing-model-file",
        W,
        "A launch `multibody configs` entry does not exist (skipped at -l time)",
        "`- sb/magic_box.yaml` that is not there",
    ),
    Rule(
        "missing-mesh",
        W,
        "A mesh file is not found after §6.2 resolution (AMBF skips the body)",
        "`mesh: link1.STL` with no such file",
    ),
    Rule(
        "mesh-unreadable",
        W,
        "An STL/OBJ/3DS mesh holds no triangles or is not a valid file (AMBF skips the body)",
        "`mesh: part.stl` that is 300 random bytes, or an OBJ with no `f` lines",
    ),
    Rule(
        "mesh-format",
        W,
        "A mesh file in a format AMBF does not load: CHAI3D reads OBJ, 3DS and STL only (AMBF skips the mesh)",
        "`mesh: part.PLY`",
    ),
    Rule(
        "obj-faces-crash-ambf",
        E,
        "An OBJ mesh has faces `f v/vt` (texture coordinates, no normals): AMBF 2.0's OBJ reader crashes on them",
        "`f 1/1 2/2 3/3`",
    ),
    Rule(
        "missing-texture",
        W,
        "A material library or texture named by an OBJ/MTL is not found",
        "`map_Kd wood.png` missing",
    ),
    Rule("missing-shader", W, "A shader, skybox or sensor mesh file is not found", "`vertex: shader.vs` missing"),
    Rule(
        "no-environment",
        E,
        "The world has no `environment` model (AMBF dereferences an uninitialised pointer)",
        "a world with only `enclosure size`",
    ),
    Rule("shape-name", E, "Unknown primitive shape name (undefined behaviour in AMBF)", "`shape: Cube`"),
    Rule(
        "collision-mesh-type", W, "Unknown `collision mesh type`; AMBF uses CONCAVE_MESH", "`collision mesh type: ''`"
    ),
    Rule("geometry-axis", W, "Primitive axis is not x/y/z; AMBF uses z", "`axis: w`"),
    Rule(
        "obj-empty-submesh",
        E,
        "A concave collision mesh (AMBF's default type) whose OBJ makes a sub-mesh without faces: a material "
        "of its library no face uses, or more objects than materials. AMBF 2.0 crashes building it",
        "`two.mtl` with a material `unused`, the mesh's `collision mesh type` left out",
    ),
    Rule(
        "inertial-offset-estimated",
        W,
        "A body colliding with a mesh has no `inertial offset` (or no `mass`): AMBF puts its centre of mass at the "
        "mean of the collision mesh's vertices (of its first sub-mesh, once per sub-mesh) and builds its collision "
        "shape there, off its visual; the finding says by how much",
        "a link's STL written from its joint, without `inertial offset`",
    ),
    Rule(
        "geometry-size",
        W,
        "A collision primitive of size 0 or less, or a capsule shorter than its two caps (AMBF gives "
        "Bullet a negative length; MuJoCo refuses both)",
        "`collision geometry: {radius: 0.05, height: 0.02}` on a capsule",
    ),
    Rule(
        "sensor-type",
        W,
        "A sensor/actuator type unknown to AMBF 2.0 (it crashes on it; newer versions and "
        "plugins define more, e.g. CONTACT)",
        "`type: CONTACT`",
    ),
    Rule("missing-parent", W, "A sensor or actuator without `parent` (AMBF skips it)", "a sensor with no parent"),
    Rule("missing-type", W, "Sensor or actuator without `type` (skipped)", "a sensor with no type"),
    Rule(
        "sensor-mesh",
        E,
        "A proximity or resistance sensor whose rays come from a `mesh` AMBF finds and reads: AMBF 2.0 "
        "crashes on it (afRayTracerSensor leaves its ray count unset for a mesh)",
        "`mesh: patch.STL` beside the model file, no `array`",
    ),
    Rule(
        "sensor-rays",
        W,
        "A sensor without exactly one of array/mesh/parametric, resolution < 2 or range < 0",
        "a proximity sensor with only `range`",
    ),
    Rule("missing-mass", W, "A body without `mass` (AMBF uses 1 kg and ignores inertia)", "a body with no mass"),
    Rule("negative-mass", E, "Negative mass", "`mass: -1`"),
    Rule("inertia", W, "Inertia not positive, or violates the triangle inequality", "`inertia: {ix: 1, iy: 1, iz: 5}`"),
    Rule(
        "static-joint",
        W,
        "A joint whose child body is static (mass 0) while its parent moves, or both static",
        "`child` with `mass: 0` on a revolute joint",
    ),
    Rule(
        "margin-size",
        W,
        "A moving body's collision cylinder with a `collision margin` above its radius or half its height: it pushes itself off what it stands on",
        "`collision margin: 0.03` on a cylinder of radius 0.02",
    ),
    Rule("bad-scale", W, "Scale not positive or implausible (< 0.001 or > 1000)", "`scale: 0`"),
    Rule("non-finite-number", E, "A number is NaN or infinite", "`mass: .nan`"),
    Rule(
        "absurd-value",
        W,
        "A magnitude above 1e6 where metres, kilograms or radians are expected",
        "`position: {x: 1e300, ...}`",
    ),
    Rule(
        "collision-groups",
        W,
        "Collision group outside 0–999 (dropped), or groups on a ghost",
        "`collision groups: [1000]`",
    ),
    Rule(
        "name-collision",
        W,
        "Two objects' names coincide once AMBF strips spaces",
        "`name: base link` and `name: baselink`",
    ),
    Rule("name-spaces", I, "A name contains spaces; AMBF removes them", "`name: base link`"),
    Rule(
        "namespace-slash",
        I,
        "A namespace that is glued to identifiers without a trailing /",
        "`namespace: /ambf/env/phantom`",
    ),
    Rule("ignored-key", I, "A key AMBF 2.x reads nowhere", "`color: red`, `enclosure size`"),
    Rule(
        "unlisted-object",
        I,
        "A BODY/JOINT/... mapping that no list names (AMBF ignores it)",
        "`BODY finger:` not in `bodies`",
    ),
    Rule(
        "camera-view",
        W,
        "A camera looks at its own location, or `up` is parallel to the view (view not set)",
        "`look at` equal to `location`",
    ),
    Rule(
        "randomize-constraints",
        W,
        "`randomize constraints: false` turns randomisation on anyway",
        "`randomize constraints: false`",
    ),
    Rule(
        "rigid-through-soft-body",
        I,
        "Every soft body: in AMBF 2.0 rigid bodies pass through it, because Bullet 2.88's soft-body collision sees "
        "convex shapes only and AMBF wraps every body's shape in a compound (a lone PLANE aside); adfkit's engines "
        "collide it with every rigid body",
        "a needle dropped on a soft skin falls through it onto the tray beneath in AMBF",
    ),
    Rule(
        "soft-body-mesh",
        W,
        "A soft body without a mesh (AMBF skips it) or with a collision primitive it does not use",
        "`soft bodies: [S]` with `mesh: ''`",
    ),
    Rule(
        "soft-body-mass", W, "A soft body without mass (AMBF uses 1 kg) or with mass <= 0", "`mass: 0` on a soft body"
    ),
    Rule(
        "volume-images",
        E,
        "A volume's `images` lacks path, prefix, format or count, or counts no slice or more "
        "than 4096 (AMBF skips the volume)",
        "`images: {path: slices/, prefix: s_, format: png}` with no count",
    ),
    Rule(
        "volume-slice-missing",
        E,
        "A volume's folder holds no slice AMBF reads (path + prefix + index 0..count + format; AMBF "
        "skips the volume), or a slice is outside the scene's tree or not a regular file",
        "`prefix: bone` for files named `bone_0.png` ...",
    ),
    Rule(
        "volume-format",
        E,
        "A volume's `format` is not one AMBF reads slices in (bmp, gif, jpg, png, ppm, raw; AMBF skips the volume)",
        "`format: tif`, or `format: .png` (AMBF adds the dot itself)",
    ),
    Rule(
        "volume-slice-gap",
        W,
        "Slice indices are missing between 0 and the last slice: AMBF stacks the slices it finds, so "
        "the ones after a gap move down",
        "`bone_0.png` .. `bone_47.png` without `bone_17.png`",
    ),
    Rule(
        "volume-slice-names",
        W,
        "A slice index is there under two names (with and without leading zeros); AMBF stacks both",
        "`plane005.png` beside `plane0005.png`",
    ),
    Rule(
        "volume-slice-opaque",
        W,
        "A colour slice without alpha: AMBF reads a colour volume's alpha, so every voxel is solid",
        "RGB slices of a segmented scan",
    ),
    Rule(
        "volume-slice-count",
        I,
        "`images: count` above the slices found (AMBF reads count as the most to search for), or a "
        "slice numbered count (AMBF reads it too)",
        "`count: 512` over a folder of 253 slices",
    ),
    Rule(
        "volume-slice-unreadable",
        E,
        "A slice of a volume is not an image Pillow reads",
        "`bone_3.png` that holds text",
    ),
    Rule("volume-too-large", E, "A volume of more than 512^3 voxels", "`count: 2000` slices of 2048x2048"),
    Rule(
        "volume-dimensions",
        E,
        "A volume's `dimensions` (times its scale) are not all positive",
        "`dimensions: {x: 0.04, y: 0, z: 0.04}`",
    ),
    Rule(
        "soft-body-fixed-nodes",
        E,
        "A fixed node index outside the nodes of the soft body's mesh (AMBF writes past its node array)",
        "`fixed nodes: [400]` on the 386-node corpus cloth",
    ),
    Rule(
        "soft-body-coefficient",
        W,
        "A soft-body stiffness, damping, friction or hardness outside Bullet's range "
        "0..1 (or a negative drag, lift, volume or time scale)",
        "`kLST: 5`",
    ),
    Rule(
        "soft-body-iterations",
        W,
        "Negative solver iterations or clusters, `piterations: 0`, or a bending distance below 2 (no link added)",
        "`bending constraint: 1`",
    ),
    Rule(
        "missing-plugin",
        W,
        "A plugin with a `path` whose library file does not exist there",
        "`plugins: [{name: p, filename: libp.so, path: ./lib}]` without lib/libp.so",
    ),
    Rule(
        "light-shadow",
        W,
        "A light without `shadow quality` (uninitialised in AMBF) or above 5",
        "a light with no shadow quality",
    ),
    Rule(
        "input-device",
        W,
        "An input device without `hardware name`, or with a missing simulated multibody",
        "a device with only `root link`",
    ),
]

RULES: dict[str, Rule] = {r.id: r for r in _RULES}
