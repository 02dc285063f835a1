"""Mass properties (volume, centre of mass, inertia tensor, principal axes) of meshes,
ADF primitives and compounds, and their ADF form (adf-format.md §7.2).

ADF stores the inertia as principal moments ``inertia: {ix, iy, iz}`` about the axes of the
inertial frame, and ``inertial offset`` as the pose of that frame (COM + principal axes) in
the body frame. ``to_adf`` turns a full tensor into that pair.

Meshes use trimesh's exact polyhedral integral (the mesh must be closed; see ``repair``).
Primitives use closed forms, in ADF's conventions: box x/y/z are FULL lengths, capsule
``height`` is the TOTAL length including both caps, ``axis`` is x, y or z.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..diagnostics import AdfError, error
from ..model import Body, Geometry, Inertia
from ..model.pose import Pose, Quat, Vec3


@dataclass(frozen=True)
class MassProperties:
    """``inertia`` is the 3x3 tensor about the COM, in the frame the COM is given in."""

    mass: float
    volume: float
    com: np.ndarray
    inertia: np.ndarray

    @property
    def density(self) -> float:
        return self.mass / self.volume if self.volume else float("nan")

    def principal(self) -> tuple[np.ndarray, np.ndarray]:
        """(moments ascending, R) with columns of R the principal axes; det(R) = +1."""
        inertia = 0.5 * (self.inertia + self.inertia.T)
        moments, axes = np.linalg.eigh(inertia)
        if np.linalg.det(axes) < 0:
            axes[:, 2] *= -1.0
        return moments, axes

    def transformed(self, pose: Pose) -> MassProperties:
        """The same body placed at ``pose`` (its frame expressed in the parent frame)."""
        rot = np.array(Quat(*pose.orientation).matrix(), dtype=float)
        com = rot @ self.com + np.asarray(pose.position, dtype=float)
        return MassProperties(self.mass, self.volume, com, rot @ self.inertia @ rot.T)

    def about(self, point) -> np.ndarray:
        """Inertia tensor about ``point`` (parallel-axis theorem)."""
        d = np.asarray(point, dtype=float) - self.com
        return self.inertia + self.mass * (np.dot(d, d) * np.eye(3) - np.outer(d, d))

    def __add__(self, other: MassProperties) -> MassProperties:
        mass = self.mass + other.mass
        com = (self.mass * self.com + other.mass * other.com) / mass
        return MassProperties(mass, self.volume + other.volume, com, self.about(com) + other.about(com))


def _scale_for(volume: float, density: float | None, mass: float | None) -> float:
    """The density to use, from a density or a total mass (exactly one of them)."""
    if (density is None) == (mass is None):
        raise ValueError("give exactly one of density or mass")
    if density is not None:
        return float(density)
    if volume <= 0:
        raise ValueError("cannot spread a mass over a zero volume")
    return float(mass) / volume


def mesh_mass_properties(mesh, density: float | None = None, mass: float | None = None) -> MassProperties:
    """Exact integral over a closed triangle mesh (trimesh). Raises AdfError for open meshes."""
    if not mesh.is_watertight:
        raise AdfError(
            error(
                "mesh-not-closed",
                "mass properties need a closed (watertight) mesh",
                hint="repair it first (adfkit.geometry.repair_mesh)",
            )
        )
    volume = float(mesh.volume)
    if volume <= 0:
        raise AdfError(
            error(
                "mesh-inverted",
                f"the mesh encloses a non-positive volume ({volume:g} m³)",
                hint="the faces point inwards; repair_mesh fixes the winding",
            )
        )
    rho = _scale_for(volume, density, mass)
    props = mesh.mass_properties  # unit density
    return MassProperties(
        rho * volume, volume, np.array(props["center_mass"], dtype=float), rho * np.array(props["inertia"], dtype=float)
    )


def _axis_index(axis: str | None) -> int:
    return {"x": 0, "y": 1}.get((axis or "z").lower(), 2)


def primitive_volume(kind: str, g: Geometry) -> float:
    k = kind.lower()
    if k == "box":
        return g.x * g.y * g.z
    if k == "sphere":
        return 4.0 / 3.0 * math.pi * g.radius**3
    if k == "cylinder":
        return math.pi * g.radius**2 * g.height
    if k == "capsule":
        r, h = g.radius, g.height - 2 * g.radius
        return math.pi * r * r * h + 4.0 / 3.0 * math.pi * r**3
    if k == "cone":
        return math.pi * g.radius**2 * g.height / 3.0
    raise ValueError(f"no volume for shape {kind!r}")


def primitive_mass_properties(
    kind: str, geometry: Geometry, pose: Pose | None = None, density: float | None = None, mass: float | None = None
) -> MassProperties:
    """Closed forms for an ADF primitive (box, sphere, cylinder, capsule, cone) at ``pose``.

    The primitive is centred on its frame (a cone on its half height, as Bullet's btCone).
    """
    k, g = kind.lower(), geometry
    volume = primitive_volume(k, g)
    m = _scale_for(volume, density, mass) * volume
    ax = _axis_index(g.axis)
    if k == "box":
        x, y, z = g.x, g.y, g.z
        diag = [m * (y * y + z * z) / 12, m * (x * x + z * z) / 12, m * (x * x + y * y) / 12]
        com_local = np.zeros(3)
    elif k == "sphere":
        diag = [0.4 * m * g.radius**2] * 3
        com_local = np.zeros(3)
    else:
        r, hgt = g.radius, g.height
        if k == "cylinder":
            axial, perp = 0.5 * m * r * r, m * (3 * r * r + hgt * hgt) / 12
            com_local = np.zeros(3)
        elif k == "capsule":
            h = hgt - 2 * r  # the cylinder part between the two hemispheres
            m_cyl = m * (math.pi * r * r * h) / volume
            m_hemi = 0.5 * (m - m_cyl)
            axial = 0.5 * m_cyl * r * r + 2 * 0.4 * m_hemi * r * r
            perp = m_cyl * (3 * r * r + h * h) / 12 + 2 * m_hemi * (0.4 * r * r + h * h / 4 + 3 * h * r / 8)
            com_local = np.zeros(3)
        elif k == "cone":  # about its centroid, which lies h/4 above the base
            axial = 0.3 * m * r * r
            perp = m * (3 * r * r / 20 + 3 * hgt * hgt / 80)
            com_local = np.zeros(3)
            com_local[ax] = -hgt / 4  # frame at half height; centroid at base + h/4
        else:
            raise ValueError(f"no mass properties for shape {kind!r}")
        diag = [perp, perp, perp]
        diag[ax] = axial
    local = MassProperties(m, volume, com_local, np.diag(diag))
    return local.transformed(pose) if pose is not None else local


def compound_mass_properties(parts: list[MassProperties]) -> MassProperties:
    if not parts:
        raise ValueError("empty compound")
    total = parts[0]
    for p in parts[1:]:
        total = total + p
    return total


def shape_entries_mass_properties(entries, density: float | None = None, mass: float | None = None) -> MassProperties:
    """Mass properties of a list of ``ShapeEntry`` (overlaps counted twice; uniform density)."""
    unit = [primitive_mass_properties(e.shape, e.geometry, e.offset or Pose(), density=1.0) for e in entries]
    total = compound_mass_properties(unit)
    rho = _scale_for(total.volume, density, mass)
    return MassProperties(total.mass * rho, total.volume, total.com, total.inertia * rho)


def to_adf(props: MassProperties) -> tuple[Inertia, Pose]:
    """ADF form: principal moments and the inertial offset (COM + principal axes)."""
    moments, axes = props.principal()
    quat = Quat.from_matrix(axes.tolist()).normalized()
    inertia = Inertia(ix=float(moments[0]), iy=float(moments[1]), iz=float(moments[2]))
    return inertia, Pose(Vec3(*map(float, props.com)), quat)


def apply_to_body(body: Body, props: MassProperties) -> Body:
    """Write mass, inertia and inertial offset into ``body`` (in place; returns it)."""
    body.mass = float(props.mass)
    body.inertia, body.inertial_offset = to_adf(props)
    return body
