"""Probes: time histories of a quantity reduced over a named particle set.

Each ``[[probe]]`` of the deck adds history columns ``probe_<set>_<quantity>``
(the LS-DYNA nodout/elout equivalent). Values are reduced over the set's
particles with ``mean``, ``min`` or ``max``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .io.fields import pressure, von_mises

_AXES = {"x": 0, "y": 1, "z": 2}
_STRESS = {"xx": (0, 0), "yy": (1, 1), "zz": (2, 2), "xy": (0, 1), "yz": (1, 2),
           "xz": (0, 2)}
_REDUCE = {"mean": np.mean, "min": np.min, "max": np.max}


@dataclass
class Probe:
    """A set's particle indices and what to record of them."""

    name: str
    idx: np.ndarray
    quantities: tuple[str, ...]
    reduce: str


def quantity(p, idx: np.ndarray, name: str) -> np.ndarray:
    """Per-particle values of a probe quantity for particles ``idx`` (SI units)."""
    kind, _, comp = name.rpartition("_")
    if kind == "velocity":
        return p.v[idx, _AXES[comp]]
    if kind == "displacement":
        return p.x[idx, _AXES[comp]] - p.x0[idx, _AXES[comp]]
    if kind == "stress":
        a, b = _STRESS[comp]
        return p.sig[idx, a, b]
    if name == "speed":
        return np.linalg.norm(p.v[idx], axis=1)
    if name == "pressure":
        return pressure(p.sig[idx])
    if name == "von_mises":
        return von_mises(p.sig[idx])
    simple = {"density": p.rho, "damage": p.damage, "internal_energy": p.e,
              "smoothing_length": p.h}
    if name in simple:
        return simple[name][idx]
    if name in p.hist_names:
        return p.hist[idx, p.hist_names.index(name)]
    raise ValueError(f"probe quantity {name!r} is not available: no material of "
                     f"this model has it (history variables: {p.hist_names or 'none'})")


def record(p, probes: list[Probe]) -> dict[str, float]:
    """History columns of every probe at the current state."""
    out = {}
    for pr in probes:
        fn = _REDUCE[pr.reduce]
        for q in pr.quantities:
            vals = quantity(p, pr.idx, q)
            out[f"probe_{pr.name}_{q}"] = float(fn(vals)) if vals.size else float("nan")
    return out
