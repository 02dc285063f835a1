"""The objects AMBF 2.0 serves over ROS for a played scene, as its source names and orders
them (no ROS needed here): which objects have a communication plugin (every rigid body,
sensor, actuator, camera and light not marked ``passive``), each one's name (the ADF `name`
with its spaces removed, plus the numeric suffix AMBF gives a duplicate), namespace and topic
(``/<namespace>/<name>/State`` and ``/Command``), and each body's joint list: AMBF's
``m_CJ_PairsActive``, the non-passive joints below the body in the order AMBF's
``addChildBodyJointPair`` builds it as the models' joints are created (afFramework.cpp),
which is the index a client's ``set_joint_pos(i, …)`` means."""

from __future__ import annotations

import re
from collections import defaultdict
from dataclasses import dataclass, field

from ..model.semantics import JointKind, joint_kind
from ..runner.names import Registry, merge_namespace
from ..runner.plan import joint_ends

DEFAULT_WORLD_NAMESPACE = "/ambf/env/"  # a scene played without a world file (AMBF always has one)
MIN_HZ, MAX_HZ = 50, 1000  # `publish frequency` defaults (adf-format.md §1.1)


def ambf_name(obj) -> str:
    """AMBF's name of an object: its `name` without spaces (adf-format.md §7.1), else the
    identifier's last word."""
    name = obj.name if obj.name is not None else obj.identifier.split(" ", 1)[-1]
    return name.replace(" ", "")


def topic_of(namespace: str, name: str) -> str:
    """ "/" + namespace + "/" + name, runs of slashes made one, as ROS cleans a name."""
    return re.sub("/{2,}", "/", "/" + namespace + "/" + name).rstrip("/")


@dataclass(eq=False)
class JointEntry:
    name: str  # AMBF's (spaces removed)
    child: str  # the child body's AMBF name
    kind: JointKind
    joint: object = None  # the ADF joint
    child_body: object = None  # its child, the engine's body
    art: object = None  # the engine's articulation holding it, None: not driven (a constraint or spring)
    index: int = -1  # its record in the articulation


@dataclass(eq=False)
class RosObject:
    kind: str  # rigid_body | sensor | actuator | camera | light
    name: str
    namespace: str
    identifier: str
    target: object  # the engine's body / sensor / actuator, the runner's cameras, the ADF light
    min_hz: int = MIN_HZ
    max_hz: int = MAX_HZ
    joints: list[JointEntry] = field(default_factory=list)
    flags: tuple = (False, True, True)  # publish children names / joint names / joint positions (file)

    @property
    def topic(self) -> str:
        return topic_of(self.namespace, self.name)


def _frequency(obj) -> tuple[int, int]:
    f = getattr(obj, "publish_frequency", None)
    lo = f.low if f is not None and f.low is not None else MIN_HZ
    hi = f.high if f is not None and f.high is not None else MAX_HZ
    return max(int(lo), 1), max(int(hi), 1)


def _remap(key: str, base: str) -> str:
    """The numeric suffix the registry (as AMBF's getNonCollidingIdx) gave a duplicate key."""
    return key[len(base) :] if key.startswith(base) else ""


class _Tree:
    """AMBF's child/joint bookkeeping of rigid bodies (afRigidBody::addChildBodyJointPair)."""

    def __init__(self) -> None:
        self.all: dict[int, list] = defaultdict(list)  # body -> [(child, joint entry, passive)]
        self.active: dict[int, list] = defaultdict(list)
        self.parents: dict[int, list] = defaultdict(list)

    def add(self, parent, child, entry: JointEntry, passive: bool) -> None:
        if parent is child:
            return
        pairs = [(c, e, p) for c, e, p in self.all[id(child)]] + [(child, entry, passive)]
        for p in self.parents[id(parent)] + [parent]:
            for c, e, pas in pairs:
                if any(x[0] is c for x in self.all[id(p)]):
                    continue
                self.all[id(p)].append((c, e, pas))
                if not pas:
                    self.active[id(p)].append(e)
        above = self.parents[id(parent)] + [parent]
        for c, _e, _p in pairs:
            mine = self.parents[id(c)]
            mine.extend(b for b in above if not any(b is x for x in mine))


def joint_lists(world) -> dict[int, list[JointEntry]]:
    """id(engine body) -> its active joints in AMBF's order."""
    driven = {id(r[0]): (art, n) for art in world.articulations for n, r in enumerate(art.records)}
    tree = _Tree()
    for m in world.scene.all_models():
        ns = m.namespace or ""
        local = Registry()
        for sb in world.bodies:
            if sb.model is m:
                local.items[sb.key] = sb
        for j in m.joints:
            kind = joint_kind(j.type)
            if kind is None:
                continue
            parent, child = joint_ends(world.registry, local, ns, j)
            if parent is None or child is None:
                continue
            art, n = driven.get(id(j), (None, -1))
            entry = JointEntry(ambf_name(j), ambf_name(child.body), kind, j, child, art, n)
            tree.add(parent, child, entry, bool(j.passive))
    return tree.active


def ros_objects(world) -> list[RosObject]:
    """Every object AMBF would serve for ``world`` (an engine world of the runner), in AMBF's
    creation order: per model its bodies, sensors, actuators, then cameras and lights."""
    out: list[RosObject] = []
    joints = joint_lists(world)
    by_model: dict[int, list] = defaultdict(list)
    for sb in world.bodies:
        by_model[id(sb.model)].append(sb)
    for m in world.scene.all_models():
        ns = m.namespace or ""
        for sb in by_model[id(m)]:
            b = sb.body
            if b.passive:
                continue
            bns = merge_namespace(ns, b.namespace)
            remap = _remap(sb.key, bns + b.identifier)
            flags = (
                bool(b.publish_children_names),
                b.publish_joint_names is not False,
                b.publish_joint_positions is not False,
            )
            lo, hi = _frequency(b)
            out.append(
                RosObject("rigid_body", ambf_name(b) + remap, bns, sb.key, sb, lo, hi, joints.get(id(sb), []), flags)
            )
        for kind, items in (("sensor", world.sensors), ("actuator", world.actuators)):
            for it in items:
                obj = it.sensor if kind == "sensor" else it.actuator
                if obj.passive or not any(obj is x for x in (m.sensors if kind == "sensor" else m.actuators)):
                    continue
                ons = merge_namespace(ns, obj.namespace)
                lo, hi = _frequency(obj)
                out.append(
                    RosObject(kind, ambf_name(obj) + _remap(it.key, ons + obj.identifier), ons, it.key, it, lo, hi)
                )
    w = world.scene.world
    wns = (w.namespace if w is not None and w.namespace is not None else DEFAULT_WORLD_NAMESPACE) or ""
    cams: dict[str, list] = {}
    for cam in world.cameras:
        cams.setdefault(cam.key, []).append(cam)
    for key, group in cams.items():
        c = group[0].camera
        if c.passive:
            continue
        owner_ns = wns if w is not None and any(c is x for x in w.cameras) else _model_ns(world, c)
        cns = merge_namespace(owner_ns, c.namespace)
        lo, hi = _frequency(c)
        out.append(RosObject("camera", ambf_name(c), cns, key, group, lo, hi))
    for light, owner_ns in _lights(world, wns):
        if light.passive:
            continue
        lns = merge_namespace(owner_ns, light.namespace)
        lo, hi = _frequency(light)
        out.append(RosObject("light", ambf_name(light), lns, lns + light.identifier, light, lo, hi))
    return out


def world_namespace(world) -> str:
    w = world.scene.world
    return (w.namespace if w is not None and w.namespace is not None else DEFAULT_WORLD_NAMESPACE) or ""


def _model_ns(world, obj) -> str:
    for m in world.scene.all_models():
        if any(obj is x for x in m.cameras) or any(obj is x for x in m.lights):
            return m.namespace or ""
    return ""


def _lights(world, wns: str):
    w = world.scene.world
    if w is not None:
        for light in w.lights:
            yield light, wns
    for m in world.scene.all_models():
        for light in m.lights:
            yield light, m.namespace or ""
