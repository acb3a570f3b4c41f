"""Output fields computed from the particle state.

:func:`particle_fields` turns a :class:`~sphdyn.state.Particles` into the
dictionary of arrays written to frames. The arrays are copies, so the state can
keep evolving after the call. ``"position"`` is always included.

Stress sign convention: ``sig`` is the Cauchy stress, tension positive. The
output pressure is positive in compression, ``p = -tr(sig) / 3``; the von Mises
stress is ``sqrt(3/2 s:s)`` with ``s = sig + p I`` the deviatoric stress.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from sphdyn.state import Particles

__all__ = ["DERIVED_FIELDS", "particle_fields", "pressure", "von_mises"]

#: Output field names (besides history variables) and what they contain.
DERIVED_FIELDS: dict[str, str] = {
    "position": "current position x [m], (N, 3)",
    "velocity": "velocity v [m/s], (N, 3)",
    "displacement": "x - x0 [m], (N, 3)",
    "stress": "Cauchy stress [Pa], tension positive, (N, 9) row-major",
    "pressure": "-tr(sig)/3 [Pa], positive in compression, (N,)",
    "von_mises": "sqrt(3/2 s:s) [Pa], s deviatoric stress, (N,)",
    "density": "current density rho [kg/m^3], (N,)",
    "mass": "mass m [kg] (kg/m in 2D), (N,)",
    "smoothing_length": "smoothing length h [m], (N,)",
    "damage": "scalar damage in [0, 1], (N,)",
    "internal_energy": "specific internal energy e [J/kg], (N,)",
    "bc": "boundary-condition flag (int8), (N,)",
    "body": "body index (int32), (N,)",
    "material": "material index (int32), (N,)",
    "swegle": "Swegle tensile-instability indicator: fraction of neighbour "
              "pairs with W''(r) sigma_n > 0 (tension positive), in [0, 1]; "
              "NaN without a solver; see docs/tensile-instability.md, (N,)",
    "phase": "mesostructure phase (int8): 0 mortar, 1 aggregate, 2 ITZ, -1 "
             "for bodies without [body.mesostructure], (N,)",
    "variation": "factor of the [material.variation] parameter (1 for "
                 "materials without variation), (N,)",
}


def pressure(sig: np.ndarray) -> np.ndarray:
    """Pressure ``-tr(sig)/3`` [Pa], positive in compression, of ``(N, 3, 3)`` stresses."""
    return -np.trace(sig, axis1=1, axis2=2) / 3.0


def von_mises(sig: np.ndarray) -> np.ndarray:
    """Von Mises equivalent stress ``sqrt(3/2 s:s)`` [Pa] of ``(N, 3, 3)`` stresses."""
    mean = np.trace(sig, axis1=1, axis2=2) / 3.0
    s = sig - mean[:, None, None] * np.eye(3)
    return np.sqrt(1.5 * np.einsum("nij,nij->n", s, s))


def _compute(p: "Particles", name: str, computed) -> np.ndarray:
    if name == "position":
        return p.x.copy()
    if name == "velocity":
        return p.v.copy()
    if name == "displacement":
        return p.x - p.x0
    if name == "stress":
        return p.sig.reshape(p.n, 9).copy()
    if name == "pressure":
        return pressure(p.sig)
    if name == "von_mises":
        return von_mises(p.sig)
    if name in computed:
        # fields evaluated by the solver on demand (e.g. the Swegle indicator)
        return np.array(computed[name](), copy=True)
    if name == "swegle":
        return np.full(p.n, np.nan)  # no solver supplied it
    if name == "phase":
        return np.full(p.n, -1, np.int8)  # no model supplied it
    if name == "variation":
        return np.ones(p.n)  # no model supplied it
    simple = {"density": "rho", "mass": "m", "smoothing_length": "h",
              "damage": "damage", "internal_energy": "e", "bc": "bc",
              "body": "body", "material": "mat"}
    if name in simple:
        return getattr(p, simple[name]).copy()
    # History variable (checked by the caller).
    return p.hist[:, p.hist_names.index(name)].copy()


def particle_fields(p: "Particles", names: list[str],
                    computed=None) -> dict[str, np.ndarray]:
    """Compute output fields from the particle state.

    Parameters
    ----------
    p : Particles
        The particle state.
    names : list of str
        Field names from :data:`DERIVED_FIELDS` or ``p.hist_names`` (a history
        column). Built-in names take precedence over history names.
        Duplicates are ignored.
    computed : mapping of str to callable, optional
        Fields the solver evaluates on demand (``Solver.output_fields()``,
        e.g. ``"swegle"``); each callable returns an (N,) array.

    Returns
    -------
    dict of str to ndarray
        ``"position"`` first, then the requested fields in the order given.
        Every array is a fresh copy.

    Raises
    ------
    ValueError
        If a name is neither a built-in field nor a history variable; the
        message lists the allowed names.
    """
    allowed = list(DERIVED_FIELDS) + [h for h in p.hist_names if h not in DERIVED_FIELDS]
    unknown = [n for n in names if n not in allowed]
    if unknown:
        raise ValueError(f"unknown output field(s) {unknown}; allowed: {allowed}")
    out: dict[str, np.ndarray] = {}
    for name in ["position", *names]:
        if name not in out:
            out[name] = _compute(p, name, computed or {})
    return out
