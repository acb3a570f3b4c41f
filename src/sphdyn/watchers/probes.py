"""Probes: time histories of a quantity reduced over a named particle or node set.

Each ``[[probe]]`` of the deck adds history columns ``probe_<set>_<quantity>``
(the LS-DYNA nodout/elout equivalent). On a particle set the quantities are
those of the output field registry (:func:`sphdyn.fields.probe_values`:
scalar fields, components of vector and tensor fields, history variables); on
a set of a mesh's nodes (LS-DYNA's nodout) those of the nodes' kinematics,
:data:`NODE_FIELDS`. Values are reduced over the set with ``mean``, ``min``
or ``max``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..fields import COMPONENTS, FIELDS, probe_values

_REDUCE = {"mean": np.mean, "min": np.min, "max": np.max}


#: the fields a probe of mesh nodes may name (with their components): what a
#: node has, its kinematics and mass
NODE_FIELDS = ("position", "velocity", "speed", "displacement", "mass")


@dataclass
class Probe:
    """A set's particle (or, with ``mesh``, that mesh's node) indices and what
    to record of them."""

    name: str
    idx: np.ndarray
    quantities: tuple[str, ...]
    reduce: str
    mesh: str = ""


def quantity(p, idx: np.ndarray, name: str, computed=None) -> np.ndarray:
    """Values of probe quantity ``name`` for particles ``idx`` (SI units);
    ``ValueError`` if the model has no such quantity."""
    return probe_values(p, name, computed)[idx]


def node_probe_field(name: str) -> str | None:
    """The field of :data:`NODE_FIELDS` that probe quantity ``name`` reads (a
    scalar field, or a component ``<vector field>_x|y|z``), None if none."""
    if name in NODE_FIELDS:
        return name if FIELDS[name].shape == "scalar" else None
    base, _, comp = name.rpartition("_")
    if base in NODE_FIELDS and comp in COMPONENTS.get(FIELDS[base].shape, {}):
        return base
    return None


def node_quantity(nodes, idx: np.ndarray, name: str) -> np.ndarray:
    """Values of probe quantity ``name`` (:func:`node_probe_field`) for mesh
    nodes ``idx`` (SI units)."""
    field = FIELDS[node_probe_field(name)]
    values = field.getter(nodes, {})
    if field.name != name:
        values = values[:, COMPONENTS[field.shape][name.rpartition("_")[2]]]
    return values[idx]


def record(p, probes: list[Probe], computed=None, meshes=None) -> dict[str, float]:
    """History columns of every probe at the current state: ``p`` the
    particles, ``meshes`` the nodes of each mesh by name."""
    out = {}
    for pr in probes:
        fn = _REDUCE[pr.reduce]
        for q in pr.quantities:
            vals = (node_quantity(meshes[pr.mesh], pr.idx, q) if pr.mesh
                    else quantity(p, pr.idx, q, computed))
            out[f"probe_{pr.name}_{q}"] = float(fn(vals)) if vals.size else float("nan")
    return out
