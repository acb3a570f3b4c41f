"""Small finite-element models for the tests: blocks of hexes or quads, solid parts."""

from __future__ import annotations

import itertools

import numpy as np

from sphdyn.materials import get_model
from sphdyn.parts.fem import SolidSettings, solid_part


def block(lo, hi, div, dim=3):
    """Structured block: points (N, 3), cells (E, 2**dim) in VTK order."""
    axes = [np.linspace(lo[k], hi[k], div[k] + 1) for k in range(dim)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, dim)
    idx = np.arange(grid.shape[0]).reshape([d + 1 for d in div])
    offs = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1),
            (0, 1, 1)][: 2 ** dim]
    cells = [[idx[tuple(np.add(c, o[:dim]))] for o in offs]
             for c in itertools.product(*[range(d) for d in div])]
    x = np.zeros((grid.shape[0], 3))
    x[:, :dim] = grid
    return x, np.array(cells, dtype=np.int64)


def material(model="elastic", **values):
    """``(model, params)`` of a material given by its SI values."""
    m = get_model(model)
    return m, m.pack(values)


def part(x, cells, dim=3, mat=None, name="mesh", **settings):
    """A solid part of steel-like elastic elements (or ``mat``)."""
    mat = mat or material(density=7850.0, E=210e9, nu=0.3)
    return solid_part(name, x, cells, dim, mat, settings=SolidSettings(**settings))
