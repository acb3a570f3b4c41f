"""Geometry: particle lattices filling primitives and particle regions.

All positions are ``(n, 3)`` float64 arrays in metres (``z = 0`` in 2D); a
lattice particle's nominal volume is ``dx**dim``.
"""

from .lattice import (
    RULES,
    SHAPES,
    box_lattice,
    cylinder_lattice,
    lattice_from_shape,
    ring_lattice,
    sphere_lattice,
)
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
]
