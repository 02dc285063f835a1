"""Sub-structures shared by several ADF elements (adf-format.md §1.1, §7.3–§7.6)."""

from __future__ import annotations

from dataclasses import dataclass

from .pose import Vec3
from .spec import Node, key


@dataclass(kw_only=True)
class Plugin(Node):
    name: str | None = key("name", "str")
    filename: str | None = key("filename", "str")
    path: str | None = key("path", "str")


@dataclass(kw_only=True)
class PublishFrequency(Node):
    low: int | None = key("low", "uint")
    high: int | None = key("high", "uint")


@dataclass(kw_only=True)
class Shaders(Node):
    path: str | None = key("path", "str")
    vertex: str | None = key("vertex", "str")
    fragment: str | None = key("fragment", "str")


@dataclass(kw_only=True)
class RGBA(Node):
    r: float | None = key("r", "float")
    g: float | None = key("g", "float")
    b: float | None = key("b", "float")
    a: float | None = key("a", "float")


@dataclass(kw_only=True)
class RGB(Node):
    r: float | None = key("r", "float")
    g: float | None = key("g", "float")
    b: float | None = key("b", "float")


@dataclass(kw_only=True)
class AmbientLevel(Node):
    level: float | None = key("level", "float")


@dataclass(kw_only=True)
class ColorComponents(Node):
    diffuse: RGB | None = key("diffuse", RGB)
    specular: RGB | None = key("specular", RGB)
    emission: RGB | None = key("emission", RGB)
    ambient: AmbientLevel | None = key("ambient", AmbientLevel)
    shininess: int | None = key("shininess", "uint")
    transparency: float | None = key("transparency", "float")


@dataclass(kw_only=True)
class Geometry(Node):
    """Dimensions of a primitive (§7.5); which keys apply depends on the shape."""

    x: float | None = key("x", "float")
    y: float | None = key("y", "float")
    z: float | None = key("z", "float")
    radius: float | None = key("radius", "float")
    height: float | None = key("height", "float")
    axis: str | None = key("axis", "str")
    normal: Vec3 | None = key("normal", "vec3")
    offset: float | None = key("offset", "float")


@dataclass(kw_only=True)
class ShapeEntry(Node):
    """One entry of `compound shape` / `compound collision shape`."""

    shape: str | None = key("shape", "str")
    geometry: Geometry | None = key("geometry", Geometry)
    offset: object | None = key("offset", "pose")


@dataclass(kw_only=True)
class Friction(Node):
    static: float | None = key("static", "float")
    rolling: float | None = key("rolling", "float")


@dataclass(kw_only=True)
class VelocityDamping(Node):
    linear: float | None = key("linear", "float")
    angular: float | None = key("angular", "float")


@dataclass(kw_only=True)
class PID(Node):
    P: float | None = key("P", "float")
    I: float | None = key("I", "float")
    D: float | None = key("D", "float")


@dataclass(kw_only=True)
class CartesianController(Node):
    linear: PID | None = key("linear", PID)
    angular: PID | None = key("angular", PID)


__all__ = [
    "Plugin",
    "PublishFrequency",
    "Shaders",
    "RGBA",
    "RGB",
    "AmbientLevel",
    "ColorComponents",
    "Geometry",
    "ShapeEntry",
    "Friction",
    "VelocityDamping",
    "PID",
    "CartesianController",
]
