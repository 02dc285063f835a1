"""Geometry for ADF bodies: mesh I/O, repair, convex decomposition, primitive fitting and
mass properties. The only package that imports trimesh, manifold3d and coacd."""
from .meshio import MESH_SUFFIXES, load_mesh

__all__ = ["MESH_SUFFIXES", "load_mesh"]
