"""Deck -> stepper: one builder per deck table, run in stage order.

:func:`build_stepper` builds the model (:func:`sphdyn.build.model.build_model`:
particles, meshes, sets), then asks each registered
:class:`~sphdyn.build.registry.Builder` for its parts, interactions and
events (the stages: :mod:`sphdyn.build.registry`). With the model this is
the only place that reads the deck; parts, interactions and the stepper see
settings objects, arrays and scalars. A new interaction or part kind is one
module with its builder (and, from another package, its deck table and an
entry point).
"""

from __future__ import annotations

import numpy as np

from ..mass_scaling import MassScaling
from .model import Model, build_model
from ..stepper import Stepper
from . import conditions, couplings, erosion, meshes, particles  # noqa: F401 (register)
from .context import BuildContext
from .registry import (ENTRY_POINT_GROUP, MESH_STAGE, Builder, Built, builders,
                       extension_tables, register)

__all__ = ["ENTRY_POINT_GROUP", "MESH_STAGE", "BuildContext", "Builder", "Built",
           "build_stepper", "builders", "extension_tables", "register"]


def build_stepper(deck, model: Model | None = None, events=(), monitors=()) -> Stepper:
    """The stepper of a validated deck (the model is built if not given);
    ``events`` come before the deck's own."""
    ctx = BuildContext(deck, build_model(deck) if model is None else model)
    out = Built(events=list(events))
    for b in builders():
        made = b.build(ctx)
        ctx.parts += made.parts
        out.extend(made)
    dt_max = deck.time.dt_max if deck.time.dt_max is not None else np.inf
    return Stepper(out.parts, out.interactions, out.events, monitors, dt_max=dt_max,
                   interaction_work=deck.output.interaction_work,
                   mass_scaling=mass_scaling(deck, ctx.model, out.parts))


def mass_scaling(deck, model: Model, parts) -> MassScaling | None:
    """The deck's ``[time.mass_scaling]`` (None without), restricted to the items of
    its ``parts`` names: an SPH part's particles of those bodies, the meshes of
    those names."""
    ms = deck.time.mass_scaling
    if ms is None:
        return None
    select = None
    if ms.parts is not None:
        names = set(ms.parts)
        bodies = [k for k, name in enumerate(model.body_names) if name in names]
        # items labelled by body (the particles) by their bodies, the others by name
        select = {part.name: (np.isin(part.kin.body, bodies) if "body" in part.kin.names()
                              else part.name in names) for part in parts}
    return MassScaling(ms.target, ms.max_added, select)
