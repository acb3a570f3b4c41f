"""Checks of a deck's model before it is built or run: its size
(:mod:`.size`) and its placement (:mod:`.placement`), in that order."""

from __future__ import annotations

import numpy as np

from .placement import check_placement
from .size import SizeEstimate, check_size


def checked_lattices(deck) -> tuple[SizeEstimate, list[np.ndarray]]:
    """The size estimate and the bodies' lattices, after every check of this module.

    :func:`check_size` first (before any particle is made), then
    :func:`check_placement` on the lattices (n_b, 3) of the bodies.
    """
    from ..geometry import lattice_from_shape

    estimate = check_size(deck)
    dim = deck.run.dimension
    lattices = [lattice_from_shape(b.geometry.model_dump(), b.dx, dim) for b in deck.body]
    check_placement(deck, lattices)
    return estimate, lattices
