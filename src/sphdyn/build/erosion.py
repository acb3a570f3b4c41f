"""Builder of the erosion events: ``[mesh.erosion]`` with its materials'
``[material.erosion]`` rules (history: ``eroded_<mesh>`` and the rest of
:meth:`sphdyn.events.ElementErosion.columns`)."""

from __future__ import annotations

import numpy as np

from ..deck import DeckError
from ..deck.errors import format_problem
from ..events import ElementErosion, ErosionRules
from ..materials import get_model
from .registry import Builder, Built, register


def erosion_rules(deck, mm) -> dict[int, ErosionRules]:
    """Material index -> its erosion rules, for the materials of mesh ``mm``;
    a deck error if none has rules or a damage rule meets a model without
    damage."""
    rules = {}
    for k in np.unique(mm.mat):
        m = deck.material[int(k)]
        if m.erosion is None:
            continue
        if m.erosion.erode is not None and not get_model(m.model).has_damage:
            raise DeckError([format_problem(
                f"material[{int(k)}] '{m.name}'.erosion.erode",
                f"model '{m.model}' has no damage variable, so the damage rule "
                "cannot apply", "use principal_strain or effective_strain, or a "
                "model with damage (cscm)")])
        e = m.erosion
        rules[int(k)] = ErosionRules(erode=e.erode, principal_strain=e.principal_strain,
                                     effective_strain=e.effective_strain,
                                     min_time_step=e.min_time_step)
    if not rules:
        names = ", ".join(f"'{deck.material[int(k)].name}'" for k in np.unique(mm.mat))
        raise DeckError([format_problem(
            f"mesh[{mm.index}] '{mm.name}'.erosion",
            f"no material of the mesh ({names}) has erosion rules",
            "add [material.erosion] (e.g. principal_strain = 0.1) to its material")])
    return rules


def build_erosion(ctx) -> Built:
    """The :class:`~sphdyn.events.ElementErosion` of every mesh with
    [mesh.erosion]."""
    out, deck = Built(), ctx.deck
    for mm in ctx.model.meshes:
        ero = mm.spec.erosion
        if ero is None:
            continue
        to_particles = ero.to == "particles"
        out.events.append(ElementErosion(
            f"erosion_{mm.name}", ctx.meshes[mm.name], erosion_rules(deck, mm),
            to=ero.to, per_element=ero.particles_per_element,
            sph=ctx.sph if to_particles else None,
            body=(ctx.model.body_names.index(f"{mm.name}_debris") if to_particles else 0),
            h_factor=deck.sph.h_factor, every=ero.every))
    return out


register(Builder("mesh.erosion", build_erosion, stage=700))
