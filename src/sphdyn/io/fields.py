"""Output fields of a frame, computed from the particle state.

:func:`particle_fields` turns a :class:`~sphdyn.state.Particles` into the
dictionary of arrays written to frames, reading the field registry
:mod:`sphdyn.fields` (names, getters, the ``position`` always written). The
arrays are copies, so the state can keep evolving after the call.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..fields import FIELDS, history_column

if TYPE_CHECKING:
    from sphdyn.state import Particles

__all__ = ["particle_fields"]


def particle_fields(p: "Particles", names: list[str],
                    computed=None) -> dict[str, np.ndarray]:
    """Compute output fields from the particle state.

    Parameters
    ----------
    p : Particles
        The particle state.
    names : list of str
        Names of registered fields (:data:`sphdyn.fields.FIELDS`) or of
        history columns ``p.hist_names``. Registered names take precedence
        over history names; a registered history field (``plastic_strain``)
        needs its column in ``p.hist_names``. Duplicates are ignored.
    computed : mapping of str to callable, optional
        Fields a part evaluates on demand (``SPHPart.fields()``, e.g.
        ``"swegle"``); each callable returns an (N,) array.

    Returns
    -------
    dict of str to ndarray
        The fields written in every frame (``"position"``) first, then the
        requested fields in the order given (not the cell fields of
        meshes only). Every array is a fresh copy.

    Raises
    ------
    ValueError
        If a name is neither a registered field nor a history variable; the
        message lists the allowed names.
    """
    built_in = [n for n, f in FIELDS.items() if f.shape != "history"]
    allowed = built_in + [h for h in p.hist_names if h not in built_in]
    unknown = [n for n in names if n not in allowed]
    if unknown:
        raise ValueError(f"unknown output field(s) {unknown}; allowed: {allowed}")
    always = [n for n, f in FIELDS.items() if f.always]
    out: dict[str, np.ndarray] = {}
    for name in [*always, *names]:
        if name in out or (name in FIELDS and FIELDS[name].getter is None):
            continue  # (a cell field of meshes only)
        if name in built_in:
            out[name] = FIELDS[name].getter(p, computed or {})
        else:
            out[name] = history_column(p, name)
    return out
