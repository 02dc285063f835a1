"""Descriptions and defaults of every ADF key (adf-format.md §3–§11), for the JSON Schema.

One line per key: ``[Class.]key | default (JSON, or empty) | description``. A ``Class.``
prefix overrides the plain entry for that element only. Kept as a table so that adding a
key to the model without a line here is caught by ``tests/test_schema.py``.
"""

from __future__ import annotations

import json

_TABLE = r"""
adf version | "1.0" | ADF version marker; must be exactly 1.0 (1, 1.00 or 2.0 make the file unloadable).
name | "" | Object name; AMBF removes every space from it. Used in ROS topic names.
namespace | "" | Namespace; merged with the enclosing namespace (concatenated verbatim unless it starts with '/').
passive | false | true: no ROS communication object for this element.
publish frequency | | ROS publish rates in Hz; both low and high are required when present.
PublishFrequency.low | 50 | Lowest ROS publish rate, Hz.
PublishFrequency.high | 1000 | Highest ROS publish rate, Hz.
plugins | [] | Plugins to load: entries {name, filename, path?}; an entry without name or filename is skipped.
Plugin.name | | Plugin name (required, or the plugin is skipped).
Plugin.filename | | Shared library file name (required, or the plugin is skipped).
Plugin.path | | Directory of the library, relative to the declaring file.
shaders | | Shader block {path, vertex, fragment}; all three required.
Shaders.path | | Shader directory, relative to the declaring file.
Shaders.vertex | | Vertex shader file inside path.
Shaders.fragment | | Fragment shader file inside path.
gravity | | Gravity vector {x, y, z}, m/s².
World.gravity | {"x": 0, "y": 0, "z": -9.8} | World gravity {x, y, z}, m/s².
Launch.world config | | World ADF file, relative to the launch file (required).
Launch.color config | | Colors file, relative to the launch file (required; never read by AMBF 2.x).
Launch.input devices config | | Input-devices ADF, relative to the launch file (required even when unused).
Launch.multibody configs | | Candidate model ADF files, relative to the launch file; picked by 0-based index with -l.
World.max iterations | 10 | Bullet maxSubSteps per step (internal step 0.001 s).
World.environment | | Model ADF loaded as the environment, relative to the world file. Effectively required.
World.enclosure | | {length, width, height} in m; only used without an environment.
Enclosure.length | | Enclosure length, m.
Enclosure.width | | Enclosure width, m.
Enclosure.height | | Enclosure height, m.
World.lights | [] | Keys of the light mappings in this file.
World.cameras | [] | Keys of the camera mappings in this file.
World.skybox | | Skybox {path, right, left, top, bottom, front, back, shaders?}; path required.
Skybox.path | | Skybox image directory, relative to the world file (required).
Skybox.right | | Right face image.
Skybox.left | | Left face image.
Skybox.top | | Top face image.
Skybox.bottom | | Bottom face image.
Skybox.front | | Front face image.
Skybox.back | | Back face image.
World.name | "World" | Ignored: the world is always named World.
InputDevices.input devices | [] | Keys of the device mappings in this file; selected by 0-based index with -i.
InputDevice.hardware name | | CHAI3D driver model name (MTMR, PHANTOM Omni, ...). Required, or the device is skipped.
InputDevice.haptic gain | | Force-feedback P gains {linear, angular}; both required when present.
HapticGain.linear | | Linear force-feedback gain.
HapticGain.angular | | Angular force-feedback gain.
InputDevice.workspace scaling | 1.0 | Scale from device to simulation workspace.
InputDevice.deadband | | Deadband; negative values are ignored with a warning.
InputDevice.max force | | Maximum force, N; overridden by the driver's maximum.
InputDevice.max jerk | | Maximum jerk.
InputDevice.orientation offset | | Orientation offset {r, p, y}, rad.
InputDevice.button mapping | | Button indices {a1, a2, g1, next mode, prev mode}; -1 means none.
ButtonMapping.a1 | | Button index for action 1.
ButtonMapping.a2 | | Button index for action 2.
ButtonMapping.g1 | | Button index for the gripper.
ButtonMapping.next mode | | Button index for the next mode.
ButtonMapping.prev mode | | Button index for the previous mode.
InputDevice.visible | false | Show the device cursor sphere.
InputDevice.visible size | 1.0 | Cursor sphere size.
InputDevice.simulated multibody | | Model ADF of the simulated device, relative to the input-devices file.
InputDevice.root link | | Body name of the simulated device's root (substring lookup).
InputDevice.location | | Pose overriding the root link's pose.
InputDevice.controller gain | | Cartesian PID {linear: {P, I?, D}, angular: {P, I?, D}} overriding the root link's.
InputDevice.enable joint control | true | Allow joint control of the simulated device.
InputDevice.pair cameras | [] | Camera names paired with this device.
ModelFile.bodies | [] | Keys of the rigid-body mappings in this file.
ModelFile.joints | [] | Keys of the joint mappings in this file.
ModelFile.soft bodies | [] | Keys of the soft-body mappings in this file.
ModelFile.ghost objects | [] | Keys of the ghost-object mappings in this file.
ModelFile.sensors | [] | Keys of the sensor mappings in this file.
ModelFile.actuators | [] | Keys of the actuator mappings in this file.
ModelFile.cameras | [] | Keys of the camera mappings in this file.
ModelFile.lights | [] | Keys of the light mappings in this file.
ModelFile.vehicles | [] | Keys of the vehicle mappings in this file.
ModelFile.volumes | [] | Keys of the volume mappings in this file.
high resolution path | "" | Base directory for visual meshes.
low resolution path | "" | Base directory for collision meshes.
ModelFile.ignore inter-collision | false | true disables collision between every pair of rigid bodies of this model.
joint erp | 0.1 | Joint error reduction parameter (ignored at model level in AMBF 2.x).
joint cfm | 0.1 | Joint constraint force mixing (ignored at model level in AMBF 2.x).
location | | Pose {position: {x, y, z}, orientation: {r, p, y}}, m / rad.
Body.location | | Pose of the body (mesh) frame in the world, m / rad.
scale | 1.0 | Scale of meshes and joint pivots (not primitive collision shapes).
mass | | Mass, kg; 0 means static. Missing: AMBF warns and uses 1 with estimated inertia.
Body.inertia | | Principal moments {ix, iy, iz}, kg·m²; estimated from the collision shape's AABB when absent.
Inertia.ix | | Moment about the inertial frame's x axis, kg·m².
Inertia.iy | | Moment about the inertial frame's y axis, kg·m².
Inertia.iz | | Moment about the inertial frame's z axis, kg·m².
inertial offset | | Pose of the centre of mass / inertial frame in the body frame.
mesh | | Visual mesh file (resolved through the high resolution paths).
mesh remove duplicates | | true merges duplicate vertices on load.
shape | | Visual primitive: Box, Sphere, Cylinder, Capsule, Cone or Plane; takes precedence over mesh.
geometry | | Dimensions of the visual primitive.
compound shape | | Visual compound: list of {shape, geometry, offset}.
visible | true | Whether the object is drawn (bodies: only with an active colour block).
color rgba | | Colour {r, g, b, a}, 0–1; all four required.
color components | | Material {diffuse, specular, emission, ambient: {level}, shininess, transparency}; transparency required.
use material | true | false ignores both colour blocks and uses the mesh's own material.
color | | Named colour; ignored by AMBF 2.x.
collision shape | | Single collision primitive; highest collision precedence.
collision geometry | | Dimensions of the collision primitive.
collision offset | | Pose of the collision primitive in the body frame; falls back to the inertial offset.
compound collision shape | | Collision compound: list of {shape, geometry, offset}; offsets in the body frame.
collision mesh | | Collision mesh file; defaults to the visual mesh name looked up in the low resolution path.
collision mesh type | "CONCAVE_MESH" | CONVEX_HULL, CONVEX_MESH, CONCAVE_MESH or POINT_CLOUD (and listed aliases).
collision margin | 0.001 | Bullet collision margin, m.
collision groups | [] | Collision groups, integers 0–999; bodies with groups collide only when they share one.
friction | | Friction {static, rolling}.
Friction.static | 0.5 | Bullet friction coefficient.
Friction.rolling | 0.01 | Bullet rolling friction coefficient.
restitution | 0.1 | Coefficient of restitution.
Body.damping | | Velocity damping {linear, angular}.
VelocityDamping.linear | 0.04 | Linear velocity damping.
VelocityDamping.angular | 0.1 | Angular velocity damping.
controller | | Cartesian PID {linear: {P, I?, D}, angular: {P, I?, D}}.
CartesianController.linear | | Linear PID gains; P and D required.
CartesianController.angular | | Angular PID gains; P and D required.
P | 10 | Proportional gain.
I | 0 | Integral gain.
D | 1 | Derivative gain.
controller output type | | FORCE, EFFORT, VELOCITY or POSITION (and lower-case forms).
publish children names | false | Publish the names of child bodies.
publish joint names | true | Publish the names of joints.
publish joint positions | true | Publish joint positions.
Geometry.x | | Box full edge length along x, m.
Geometry.y | | Box full edge length along y, m.
Geometry.z | | Box full edge length along z, m.
Geometry.radius | | Radius, m.
Geometry.height | | Full height (capsule: including the caps), m.
Geometry.axis | "z" | Axis of a cylinder, capsule or cone: x, y or z.
Geometry.normal | | Plane normal {x, y, z}.
Geometry.offset | | Plane offset: n·x = offset.
ShapeEntry.shape | | Primitive: Box, Sphere, Cylinder, Capsule, Cone or Plane.
ShapeEntry.geometry | | Dimensions of the primitive.
ShapeEntry.offset | | Pose of this part in the body frame.
RGBA.r | | Red, 0–1.
RGBA.g | | Green, 0–1.
RGBA.b | | Blue, 0–1.
RGBA.a | | Alpha, 0–1.
RGB.r | | Red, 0–1.
RGB.g | | Green, 0–1.
RGB.b | | Blue, 0–1.
ColorComponents.diffuse | {"r": 0.7, "g": 0.7, "b": 0.7} | Diffuse colour.
ColorComponents.specular | {"r": 1, "g": 1, "b": 1} | Specular colour.
ColorComponents.emission | {"r": 0, "g": 0, "b": 0} | Emission colour.
ColorComponents.ambient | | Ambient {level}: ambient = level × diffuse.
AmbientLevel.level | 0.3 | Ambient level.
ColorComponents.shininess | 64 | Shininess.
ColorComponents.transparency | | Transparency, 0–1 (required).
SoftBody.config | | Bullet btSoftBody settings.
SoftBody.randomize constraints | | Any value (even false) turns constraint randomisation on.
SoftBodyConfig.kLST | 1 | Linear stiffness coefficient.
SoftBodyConfig.kAST | 1 | Area/angular stiffness coefficient.
SoftBodyConfig.kVST | 1 | Volume stiffness coefficient.
SoftBodyConfig.kVCF | 1 | Velocities correction factor.
SoftBodyConfig.kDP | 0 | Damping coefficient.
SoftBodyConfig.kDG | 0 | Drag coefficient.
SoftBodyConfig.kLF | 0 | Lift coefficient.
SoftBodyConfig.kPR | 0 | Pressure coefficient.
SoftBodyConfig.kVC | 0 | Volume conservation coefficient.
SoftBodyConfig.kDF | 0.2 | Dynamic friction coefficient.
SoftBodyConfig.kMT | 0 | Pose matching coefficient; setting it enables pose matching.
SoftBodyConfig.kCHR | 1 | Rigid contacts hardness.
SoftBodyConfig.kKHR | 0.1 | Kinetic contacts hardness.
SoftBodyConfig.kSHR | 1 | Soft contacts hardness.
SoftBodyConfig.kAHR | 0.7 | Anchors hardness.
SoftBodyConfig.kSRHR_CL | 0.1 | Soft vs rigid hardness (cluster only).
SoftBodyConfig.kSKHR_CL | 1 | Soft vs kinetic hardness (cluster only).
SoftBodyConfig.kSSHR_CL | 0.5 | Soft vs soft hardness (cluster only).
SoftBodyConfig.kSR_SPLT_CL | 0.5 | Soft vs rigid impulse split (cluster only).
SoftBodyConfig.kSK_SPLT_CL | 0.5 | Soft vs kinetic impulse split (cluster only).
SoftBodyConfig.kSS_SPLT_CL | 0.5 | Soft vs soft impulse split (cluster only).
SoftBodyConfig.maxvolume | 1 | Maximum volume ratio for pose.
SoftBodyConfig.timescale | 1 | Time scale.
SoftBodyConfig.viterations | 0 | Velocity solver iterations.
SoftBodyConfig.piterations | 1 | Position solver iterations.
SoftBodyConfig.diterations | 0 | Drift solver iterations.
SoftBodyConfig.citerations | 4 | Cluster solver iterations.
SoftBodyConfig.flags | 1 | Collision flags bitmask (m_cfg.collisions).
SoftBodyConfig.bending constraint | | Distance of bending constraints; enables them.
SoftBodyConfig.clusters | | Number of clusters; enables clustering.
SoftBodyConfig.fixed nodes | | Node indices given mass 0.
parent | | Parent body (exact, then unique-substring lookup).
Ghost.location | | Pose; relative to the parent body frame when parent is set.
Joint.parent | "" | Parent body identifier (exact, then unique-substring lookup).
Joint.child | "" | Child body identifier (exact, then unique-substring lookup).
Joint.type | | revolute, hinge, continuous, prismatic, slider, fixed, linear spring, spring, torsion spring, torsional spring, angular spring, p2p, cone twist, six dof, six dof spring (required).
Joint.parent pivot | | Joint origin in the parent body frame, m (required).
Joint.child pivot | | Joint origin in the child body frame, m (required).
Joint.parent axis | | Joint axis in the parent body frame (required, non-zero).
Joint.child axis | | Joint axis in the child body frame (required, non-zero).
Joint.joint limits | | {low, high}; {x, y, z} for cone twist; {linear: {low, high}, angular: {low, high}} for six dof.
JointLimits.low | | Lower limit, rad or m.
JointLimits.high | | Upper limit, rad or m.
JointLimits.x | 0.7 | Cone-twist swing limit about x, rad.
JointLimits.y | 0.7 | Cone-twist swing limit about y, rad.
JointLimits.z | 0.7 | Cone-twist twist limit about z, rad.
JointLimits.linear | | Six-dof linear limits {low: {x,y,z}, high: {x,y,z}}, m.
JointLimits.angular | | Six-dof angular limits {low: {x,y,z}, high: {x,y,z}}, rad.
Vec3Range.low | | Lower limits {x, y, z}.
Vec3Range.high | | Upper limits {x, y, z}.
Joint.offset | 0 | Rotation of the child about the axis at joint zero, rad.
Joint.child offset | 0 | Alias of offset (offset wins).
Joint.joint offset | 0 | Rotation of the joint frame about the parent axis, rad.
Joint.damping | 0 | Spring damping; six dof spring: {linear: {x,y,z}, angular: {x,y,z}}.
Joint.stiffness | 0 | Spring stiffness; six dof spring: {linear, angular} blocks.
Joint.equilibrium point | | Spring equilibrium; defaults to the middle of the limits.
AxesGains.linear | | Per-axis linear values {x, y, z}.
AxesGains.angular | | Per-axis angular values {x, y, z}.
Joint.max motor impulse | 0.1 | Hinge motor impulse (slider: force = impulse / 0.001).
Joint.controller | | Joint PID {P?, I?, D?}.
Joint.enable feedback | false | Bullet joint feedback (reaction forces).
Joint.enable motor | true | Present only with enable feedback: AMBF reads enable feedback's value here.
Joint.ignore inter-collision | true | true disables collision between the two joined bodies.
Sensor.type | | Proximity or Resistance (any case form listed); required.
Sensor.location | | Pose in the parent body frame.
Sensor.range | 0.5 | Ray length, m.
Sensor.visible | false | Draw the rays.
Sensor.visible size | 0.02 | Size of drawn ray markers.
Sensor.array | | Rays {offset: {x,y,z}, direction: {x,y,z}} in the sensor frame.
Ray.offset | | Ray start in the sensor frame.
Ray.direction | | Ray direction (not normalised).
Sensor.mesh | | Mesh whose triangle normals define rays; relative to the model directory.
Sensor.parametric | | Ray fan {resolution ≥ 2, horizontal angle, vertical angle, start offset}.
Parametric.resolution | | Rays per side (≥ 2).
Parametric.horizontal angle | | Horizontal fan angle, rad.
Parametric.vertical angle | | Vertical fan angle, rad.
Parametric.start offset | | Start offset along each ray, m.
Sensor.friction | | Resistance friction {static, damping, dynamic, variable}.
ResistanceFriction.static | 0 | Static friction.
ResistanceFriction.damping | 0.1 | Damping.
ResistanceFriction.dynamic | 0 | Dynamic friction.
ResistanceFriction.variable | false | Variable friction.
Sensor.contact area | 0.1 | Contact area.
Sensor.contact stiffness | 0 | Contact stiffness.
Sensor.contact damping | 0 | Contact damping.
Actuator.type | | Constraint (any case form listed); required.
Actuator.location | | Pose in the parent body frame.
Actuator.visible | false | Draw the actuator.
Actuator.visible size | 0.02 | Size of the drawn marker.
Actuator.max impulse | 10 | Read by AMBF 2.0 and not used: its constraint holds without a limit.
Actuator.tau | 1 | Read by AMBF 2.0 and not used.
Camera.location | {"x": 0, "y": 0, "z": 0} | Camera position {x, y, z} (not a pose).
Camera.look at | {"x": 0, "y": 0, "z": 0} | Point looked at {x, y, z}.
Camera.up | {"x": 0, "y": 0, "z": 1} | Up vector {x, y, z}.
Camera.clipping plane | | {near, far} in m; both required.
ClippingPlane.near | 0.1 | Near clipping distance, m.
ClippingPlane.far | 10 | Far clipping distance, m.
Camera.field view angle | 0.7 | Vertical field of view, rad.
Camera.orthographic view width | | Orthographic view width, m; its presence switches to orthographic.
Camera.stereo | | {mode, eye separation, focal length}; all required.
Stereo.mode | | Stereo mode (any value turns passive stereo on).
Stereo.eye separation | 0.2 | Eye separation, m.
Stereo.focal length | 0.5 | Focal length, m.
Camera.monitor | 0 | Display index for the window.
Camera.visible | true | Show a window.
Camera.controlling devices | [] | Input devices that drive this camera.
Camera.publish image | false | Stream images.
Camera.publish depth | false | Stream depth.
Camera.publish image interval | 1 | Publish every Nth render.
Camera.publish depth interval | 10 | Publish depth every Nth render.
Camera.publish image resolution | {"width": 640, "height": 480} | Frame-buffer size {width, height}.
Camera.publish depth resolution | {"width": 640, "height": 480} | Parsed, but depth uses the image resolution.
Resolution.width | | Width, pixels.
Resolution.height | | Height, pixels.
Camera.publish depth noise | | Depth noise {mean, std_dev / std dev, bias}; mean required.
DepthNoise.mean | 0.1 | Noise mean.
DepthNoise.std_dev | 0.001 | Noise standard deviation.
DepthNoise.std dev | 0.001 | Noise standard deviation (spaced spelling).
DepthNoise.bias | 0 | Noise bias.
Camera.preprocessing shaders | | Shader block for preprocessing.
Camera.depth compute shaders | | Shader block computing depth.
Camera.multipass | false | Multipass transparency (needed for shadows).
Camera.mouse control multipliers | | Multipliers {pan, rotate, scroll, arcball}.
MouseMultipliers.pan | 1 | Pan multiplier.
MouseMultipliers.rotate | 1 | Rotate multiplier.
MouseMultipliers.scroll | 1 | Scroll multiplier.
MouseMultipliers.arcball | 1 | Arcball multiplier.
Light.location | {"x": 0, "y": 0, "z": 0} | Light position {x, y, z} (not a pose).
Light.direction | {"x": 0, "y": 0, "z": 0} | Direction; becomes the light's +X axis.
Light.spot exponent | 0.7 | Spot exponent.
Light.cutoff angle | 0.7 | Cutoff angle, rad.
Light.shadow quality | | 0 (no shadow) to 5; always set it (uninitialised otherwise).
Light.attenuation | | {constant, linear, quadratic}.
Attenuation.constant | 1 | Constant attenuation.
Attenuation.linear | 0 | Linear attenuation.
Attenuation.quadratic | 0 | Quadratic attenuation.
Vehicle.chassis | | Chassis body name (from an earlier-loaded model).
Vehicle.high resolution path | | Parsed but unused.
Vehicle.wheels | | Wheels: each has body or mesh.
Wheel.body | | Wheel body name (made static).
Wheel.mesh | | Wheel mesh path, relative to the working directory.
Wheel.width | | Wheel width, m.
Wheel.radius | | Wheel radius, m.
Wheel.friction | | Wheel friction.
Wheel.suspension | | {stiffness, damping, compression, rest length}; all required.
Suspension.stiffness | | Suspension stiffness.
Suspension.damping | | Suspension damping.
Suspension.compression | | Suspension compression.
Suspension.rest length | | Suspension rest length, m.
Wheel.roll influence | | Roll influence.
Wheel.down direction | | Down direction {x, y, z}.
Wheel.axel direction | | Axle direction {x, y, z} (spelled axel).
Wheel.offset | | Wheel offset {x, y, z} in the chassis frame.
Wheel.front | false | Front (steered) wheel.
Wheel.steering limits | | {low, high}, rad.
SteeringLimits.low | | Lower steering limit, rad.
SteeringLimits.high | | Upper steering limit, rad.
Wheel.max engine power | | Maximum engine power.
Wheel.max brake power | 0 | Maximum brake power.
Volume.dimensions | {"x": 1, "y": 1, "z": 1} | Size {x, y, z} in m, multiplied by scale.
Volume.iso-surface value | 0.5 | Iso-surface value.
Volume.optical density | 1 | Optical density.
Volume.quality | 0.5 | Rendering quality.
Volume.images | | {path, prefix, format, count}; all required.
VolumeImages.path | | Image directory.
VolumeImages.prefix | | Image file prefix.
VolumeImages.format | | Image file format.
VolumeImages.count | | Number of images.
"""


def _parse() -> dict[str, tuple[object, str]]:
    out: dict[str, tuple[object, str]] = {}
    for line in _TABLE.strip().splitlines():
        key, default, text = (part.strip() for part in line.split("|", 2))
        out[key] = (json.loads(default) if default else None, text)
    return out


TABLE = _parse()


def describe(cls_name: str, key: str) -> tuple[object, str] | None:
    """(default or None, description) of ``key`` in element ``cls_name``."""
    return TABLE.get(f"{cls_name}.{key}") or TABLE.get(key)
