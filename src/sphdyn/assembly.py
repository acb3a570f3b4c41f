"""Deck -> stepper: the SPH part, walls, contact, events and the time-step limits.

With :mod:`sphdyn.model` (particles, materials, sets, probes) this is the
only place that reads the deck; parts, interactions and the stepper see
settings objects, arrays and scalars.
"""

from __future__ import annotations

import numpy as np

from .events import DomainExit
from .interactions import Gravity, ParticleContact, Wall
from .mesh_assembly import erosion_events, mesh_interactions, mesh_part
from .kernels import KernelContext
from .mass_scaling import MassScaling
from .model import Model, build_model, debris_meshes, sublayer_meshes
from .parts import SPHPart, SPHSettings
from .stepper import Stepper


def sph_settings(deck, converted: int = 0, sublayer: int = 0,
                 debris: int = 0) -> SPHSettings:
    """The SPH scheme's settings from ``[sph]``, ``[time]`` and the bodies;
    ``converted`` bodies made of mesh elements follow after the deck's, with
    the [sph] formulation and artificial stress, then the ``sublayer`` bodies
    of bars and the ``debris`` bodies of eroded elements, updated-Lagrangian
    (a bar's particles follow its nodes; debris has no reference shape)."""
    sph = deck.sph
    tl = tuple((b.formulation or sph.formulation) == "total_lagrangian" for b in deck.body)
    eps = tuple(sph.artificial_stress.epsilon if b.artificial_stress is None
                else b.artificial_stress for b in deck.body)
    tl += ((sph.formulation == "total_lagrangian",) * converted
           + (False,) * (sublayer + debris))
    eps += (sph.artificial_stress.epsilon,) * (converted + sublayer + debris)
    return SPHSettings(
        correction=bool(sph.correction), alpha=sph.viscosity.alpha,
        beta=sph.viscosity.beta, xsph=sph.xsph,
        benz=sph.smoothing_length.mode == "benz",
        h_min_factor=sph.smoothing_length.min_factor,
        h_max_factor=sph.smoothing_length.max_factor,
        skin_factor=sph.neighbours.skin_factor, cfl=deck.time.cfl,
        stress_exponent=sph.artificial_stress.n, epsilon=eps, total_lagrangian=tl,
        hourglass=sph.hourglass, reference_update_every=sph.reference_update_every,
        crack_band=sph.crack_band,
        density_limits=tuple((m.min_density_factor, m.max_density_factor)
                             for m in deck.material),
        viscosity=tuple(material_viscosity(sph.viscosity, m) for m in deck.material),
        time_step_factor=tuple(m.time_step_factor for m in deck.material))


def material_viscosity(default, material) -> tuple[float, float]:
    """``(alpha, beta)`` of a material: its [material.viscosity], each absent key
    the [sph.viscosity] ``default``'s."""
    own = material.viscosity
    alpha = default.alpha if own is None or own.alpha is None else own.alpha
    beta = default.beta if own is None or own.beta is None else own.beta
    return alpha, beta


def contact_on(deck, settings: SPHSettings) -> bool:
    """``[contact] enabled``, by default on with two or more bodies of which one
    is total-Lagrangian (their kernels never see the other bodies)."""
    if deck.contact.enabled is not None:
        return bool(deck.contact.enabled)
    return len(settings.total_lagrangian) >= 2 and any(settings.total_lagrangian)


def build_stepper(deck, model: Model | None = None, events=(), monitors=()) -> Stepper:
    """The stepper of a validated deck (the model is built if not given)."""
    model = build_model(deck) if model is None else model
    p = model.particles
    parts, interactions, part = [], [], None
    debris = len(debris_meshes(model.meshes))
    sublayer = len(sublayer_meshes(model.meshes))
    if p.n or debris:
        kernel = KernelContext.named(deck.sph.kernel, p.dim, deck.sph.support_scale)
        settings = sph_settings(
            deck, len(model.body_names) - len(deck.body) - sublayer - debris, sublayer,
            debris)
        part = SPHPart(p, model.groups, kernel, settings, phase=model.phase,
                       variation=model.variation)
        parts.append(part)
        if contact_on(deck, settings):
            interactions.append(ParticleContact(part, deck.contact.alpha,
                                                deck.contact.distance_factor))
        interactions += [Wall(spec, part) for spec in model.walls]
    meshes = {mm.name: mesh_part(deck, mm) for mm in model.meshes}
    parts += meshes.values()
    interactions += mesh_interactions(deck, model, part, meshes)
    if deck.run.gravity is not None and any(deck.run.gravity):
        interactions += [Gravity(q, deck.run.gravity) for q in parts]
    events = list(events) + erosion_events(deck, model, part, meshes)
    if part is not None and deck.domain.outside == "remove":
        events.append(DomainExit(part, model.domain_lo, model.domain_hi))
    dt_max = deck.time.dt_max if deck.time.dt_max is not None else np.inf
    return Stepper(parts, interactions, events, monitors, dt_max=dt_max,
                   interaction_work=deck.output.interaction_work,
                   mass_scaling=mass_scaling(deck, model, parts))


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
        select = {part.name: (np.isin(part.p.body, bodies) if part.kind == "sph"
                              else part.name in names) for part in parts}
    return MassScaling(ms.target, ms.max_added, select)
