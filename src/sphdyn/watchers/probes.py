"""Probes: time histories of a quantity reduced over a named particle set.

Each ``[[probe]]`` of the deck adds history columns ``probe_<set>_<quantity>``
(the LS-DYNA nodout/elout equivalent). The quantities are those of the output
field registry (:func:`sphdyn.fields.probe_values`: scalar fields, components
of vector and tensor fields, history variables); values are reduced over the
set's particles with ``mean``, ``min`` or ``max``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..fields import probe_values

_REDUCE = {"mean": np.mean, "min": np.min, "max": np.max}


@dataclass
class Probe:
    """A set's particle indices and what to record of them."""

    name: str
    idx: np.ndarray
    quantities: tuple[str, ...]
    reduce: str


def quantity(p, idx: np.ndarray, name: str, computed=None) -> np.ndarray:
    """Values of probe quantity ``name`` for particles ``idx`` (SI units);
    ``ValueError`` if the model has no such quantity."""
    return probe_values(p, name, computed)[idx]


def record(p, probes: list[Probe], computed=None) -> dict[str, float]:
    """History columns of every probe at the current state."""
    out = {}
    for pr in probes:
        fn = _REDUCE[pr.reduce]
        for q in pr.quantities:
            vals = quantity(p, pr.idx, q, computed)
            out[f"probe_{pr.name}_{q}"] = float(fn(vals)) if vals.size else float("nan")
    return out
