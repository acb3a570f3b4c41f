"""Geometry: particle lattices filling primitives, particle regions, and
finite-element meshes (generated or read from Gmsh / Abaqus files).

All positions are ``(n, 3)`` float64 arrays in metres (``z = 0`` in 2D); a
lattice particle's nominal volume is ``dx**dim``.
"""

from .convert import element_centroids, elements_to_particles
from .lattice import (
    RULES,
    SHAPES,
    box_lattice,
    cylinder_lattice,
    lattice_from_shape,
    ring_lattice,
    sphere_lattice,
)
from .mesh import MESH_KINDS, MeshData, check_elements, element_jacobians
from .mesh_blocks import block_mesh, line_mesh, polyline_mesh, prism_mesh
from .mesh_files import read_mesh
from .regions import REGION_SHAPES, bounding_box, select

__all__ = [
    "RULES",
    "SHAPES",
    "REGION_SHAPES",
    "box_lattice",
    "cylinder_lattice",
    "ring_lattice",
    "sphere_lattice",
    "lattice_from_shape",
    "select",
    "bounding_box",
    "MESH_KINDS",
    "MeshData",
    "block_mesh",
    "line_mesh",
    "polyline_mesh",
    "prism_mesh",
    "read_mesh",
    "element_jacobians",
    "check_elements",
    "element_centroids",
    "elements_to_particles",
]
