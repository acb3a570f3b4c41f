"""Small finite-element models for the tests: blocks of hexes or quads, solid parts."""

from __future__ import annotations

from sphdyn.geometry.mesh_blocks import block_mesh
from sphdyn.materials import get_model
from sphdyn.parts.fem import SolidSettings, solid_part


def block(lo, hi, div, dim=3):
    """Structured block (:func:`sphdyn.geometry.mesh_blocks.block_mesh`): points (N, 3), cells."""
    mesh = block_mesh(lo, hi, div[:dim], dim)
    return mesh.points.copy(), mesh.cells.copy()


def material(model="elastic", **values):
    """``(model, params)`` of a material given by its SI values."""
    m = get_model(model)
    return m, m.pack(values)


def part(x, cells, dim=3, mat=None, name="mesh", **settings):
    """A solid part of steel-like elastic elements (or ``mat``)."""
    mat = mat or material(density=7850.0, E=210e9, nu=0.3)
    return solid_part(name, x, cells, dim, mat, settings=SolidSettings(**settings))
