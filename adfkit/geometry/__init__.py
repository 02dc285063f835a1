"""Geometry for ADF bodies: mesh I/O, repair, convex decomposition, primitive fitting and
mass properties. The only package that imports trimesh, manifold3d and coacd."""

__all__ = ["MESH_SUFFIXES", "load_mesh"]
# Heavier pieces are imported from their modules (adfkit.geometry.repair, .decompose, .mass,
# .primitives) so that ``load_mesh`` does not pull in manifold3d or coacd.


def __getattr__(name):  # lazy: ``adfkit.geometry.meshcheck`` (used by the validator) needs no trimesh
    if name in __all__:
        from . import meshio

        return getattr(meshio, name)
    raise AttributeError(name)
