"""Row statistics of a neighbour list: largest and mean number of neighbours."""

from __future__ import annotations

import numpy as np


def max_neighbours(nl):
    """Largest row length of the list (0 for an empty list)."""
    if nl.n == 0:
        return 0
    return int(np.diff(nl.offsets).max())


def mean_neighbours(nl):
    """Mean row length over the particles active at the build (0.0 if none)."""
    n_act = nl.n if nl.active_ref is None else int(nl.active_ref.sum())
    if n_act == 0:
        return 0.0
    return nl.nnz / n_act
