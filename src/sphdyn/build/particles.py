"""Builders of the particles: ``[[body]]`` (the SPH part), ``[contact]``,
``[[wall]]`` on particles, the bodies' damping and ``[domain]``."""

from __future__ import annotations

import numpy as np

from ..events import DomainExit
from ..interactions import ParticleContact, Wall
from ..interactions.nodal import MassDamping
from ..kernels import KernelContext
from .model import debris_meshes, sublayer_meshes
from ..parts import SPHPart, SPHSettings
from .registry import Builder, Built, register


def sph_settings(deck, converted: int = 0, sublayer: int = 0,
                 debris: int = 0) -> SPHSettings:
    """The SPH scheme's settings from ``[sph]`` and the bodies;
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
        skin_factor=sph.neighbours.skin_factor, cfl=sph.cfl,
        stress_exponent=sph.artificial_stress.n, epsilon=eps, total_lagrangian=tl,
        hourglass_coefficient=sph.hourglass_coefficient,
        reference_update_every=sph.reference_update_every,
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


def build_particles(ctx) -> Built:
    """The SPH part of every particle (the deck's bodies, then the converted,
    sublayer and debris bodies of meshes); none without particles."""
    deck, model = ctx.deck, ctx.model
    debris = len(debris_meshes(model.meshes))
    sublayer = len(sublayer_meshes(model.meshes))
    if not (model.particles.n or debris):
        return Built()
    p = model.particles
    kernel = KernelContext.named(deck.sph.kernel, p.dim, deck.sph.support_scale)
    settings = sph_settings(
        deck, len(model.body_names) - len(deck.body) - sublayer - debris, sublayer, debris)
    ctx.sph = SPHPart(p, model.groups, kernel, settings, phase=model.phase,
                      variation=model.variation)
    return Built(parts=[ctx.sph])


def build_contact(ctx) -> Built:
    """``[contact]``: the particle contact between bodies, when on (:func:`contact_on`)."""
    if ctx.sph is None or not contact_on(ctx.deck, ctx.sph.s):
        return Built()
    c = ctx.deck.contact
    return Built(interactions=[ParticleContact(ctx.sph, c.alpha, c.distance_factor)])


def build_walls(ctx) -> Built:
    """``[[wall]]``: each rigid wall on the particles."""
    if ctx.sph is None:
        return Built()
    return Built(interactions=[Wall(spec, ctx.sph) for spec in ctx.model.walls])


def build_body_damping(ctx) -> Built:
    """``[[body]] damping``: mass-proportional damping of a body's particles."""
    return Built(interactions=[
        MassDamping(body.name, ctx.sph, np.flatnonzero(ctx.sph.p.body == b), body.damping)
        for b, body in enumerate(ctx.deck.body) if body.damping > 0.0])


def build_domain_exit(ctx) -> Built:
    """``[domain] outside = "remove"``: particles leaving the box are removed."""
    if ctx.sph is None or ctx.deck.domain.outside != "remove":
        return Built()
    return Built(events=[DomainExit(ctx.sph, ctx.model.domain_lo, ctx.model.domain_hi)])


register(Builder("body", build_particles, stage=100))
register(Builder("contact", build_contact, stage=200))
register(Builder("wall", build_walls, stage=210))
register(Builder("body.damping", build_body_damping, stage=330))
register(Builder("domain", build_domain_exit, stage=710))
