"""Builders of the couplings between particles and elements, run mesh by
mesh: ``[mesh.convert]`` (penalty, tied or hybrid), ``[mesh.sublayer]``,
``[mesh.contact]`` and the debris coupling of ``[mesh.erosion] to =
"particles"``."""

from __future__ import annotations

import numpy as np

from ..deck import DeckError
from ..deck.errors import format_problem
from ..interactions import HybridCoupling, PenaltyCoupling, TiedCoupling
from ..interactions.nodal import MassDamping
from ..interactions.sublayer import SublayerCoupling
from .meshes import PLURAL
from .registry import Builder, Built, register


def _converted_coupling(mm, sph_part, part, rows) -> list:
    """The coupling of a mesh's converted particles (``rows``, (k,), then the
    hybrid layer's) with its remaining elements."""
    conv = mm.converted.spec
    where = f"mesh[{mm.index}] '{mm.name}'.convert.coupling"
    name = f"{mm.name}_coupling"
    if conv.coupling == "none":
        return []
    try:
        if conv.coupling == "hybrid":
            hy = mm.converted.hybrid
            return [HybridCoupling(name, sph_part, part, rows[mm.converted.x.shape[0]:],
                                   hy.elem, hy.xi)]
        if conv.coupling == "tied":
            coupling = TiedCoupling(name, sph_part, part, tie_factor=(
                1.0 if conv.tie_factor is None else conv.tie_factor))
    except ValueError as exc:
        raise DeckError([format_problem(where, str(exc).split(": ", 1)[-1],
                                        "see the coupling's section in docs/deck.md")]) from None
    if conv.coupling == "tied":
        found = coupling.slaves.size
    else:
        coupling = PenaltyCoupling(name, sph_part, part, stiffness=conv.stiffness,
                                   alpha=conv.alpha, thickness_factor=conv.thickness_factor,
                                   friction=conv.friction,
                                   tie_factor=conv.tie_factor or 0.0,
                                   stiffness_step=conv.stiffness_step)
        found = coupling.cand.size
    if found == 0:
        raise DeckError([format_problem(
            where, "the coupling finds no particle near the remaining elements' faces",
            "make the converted region touch the rest of the mesh"
            + (" (or raise tie_factor)" if conv.coupling == "tied" else ""))])
    return [coupling]


def build_convert(ctx, mm) -> Built:
    """``[mesh.convert]``: the converted particles' coupling with the remaining
    elements, after the damping of those particles that the mesh does not move
    (its ``slaves``), which are damped like the mesh."""
    if mm.converted is None:
        return Built()
    rows = ctx.body_rows(mm.name)
    coupling = _converted_coupling(mm, ctx.sph, ctx.meshes[mm.name], rows)
    out = Built()
    if mm.spec.damping > 0.0:
        slaves = np.concatenate([np.zeros(0, np.int64)]
                                + [getattr(c, "slaves", np.zeros(0, np.int64))
                                   for c in coupling])
        out.interactions.append(MassDamping(f"{mm.name}_particles", ctx.sph,
                                            np.setdiff1d(rows, slaves), mm.spec.damping))
    out.interactions += coupling  # after every other interaction on the particles
    return out


def build_sublayer(ctx, mm) -> Built:
    """``[mesh.sublayer]``: the bond between a bar's elements and its particles."""
    if mm.spec.sublayer is None:
        return Built()
    part = ctx.meshes[mm.name]
    return Built(interactions=[SublayerCoupling(
        f"{mm.name}_sublayer", ctx.sph, part, ctx.body_rows(f"{mm.name}_sublayer"),
        np.arange(part.kin.n))])


def _contact_meshes(ctx, mm) -> list[str]:
    """The solid meshes of ``[mesh.contact] meshes`` (their nodes are slaves of
    ``mm``'s faces); a line mesh or ``mm`` itself is a deck error."""
    kinds = {m.name: m.element for m in ctx.model.meshes}
    where = f"mesh[{mm.index}] '{mm.name}'.contact.meshes"
    for slave in mm.spec.contact.meshes:
        if slave == mm.name:
            raise DeckError([format_problem(where, f"mesh '{slave}' is this mesh: a "
                                            "mesh does not contact its own faces",
                                            "name the other mesh that meets these faces")])
        if kinds[slave] != "solid":
            raise DeckError([format_problem(where, f"mesh '{slave}' is a line of "
                                            f"{PLURAL[kinds[slave]]}, not solid elements",
                                            "list solid meshes only (a bar inside a solid "
                                            "mesh: embed)")])
    return list(mm.spec.contact.meshes)


def build_contact(ctx, mm) -> Built:
    """``[mesh.contact]``: penalty contact of the particles (if any) and of the
    listed meshes' nodes with this mesh's faces."""
    con = mm.spec.contact
    if con is None:
        return Built()
    part = ctx.meshes[mm.name]
    keys = dict(stiffness=con.stiffness, alpha=con.alpha,
                thickness_factor=con.thickness_factor, friction=con.friction,
                stiffness_step=con.stiffness_step)
    out = Built()
    if ctx.sph is not None:  # a model of meshes only has no particles
        out.interactions.append(PenaltyCoupling(f"{mm.name}_contact", ctx.sph, part,
                                                **keys))
    for slave in _contact_meshes(ctx, mm):
        out.interactions.append(PenaltyCoupling(f"{mm.name}_contact_{slave}",
                                                ctx.meshes[slave], part, **keys))
    return out


def build_debris_contact(ctx, mm) -> Built:
    """``[mesh.erosion] to = "particles"``: the debris meets the remaining
    elements by penalty, unless ``[mesh.contact]`` or a ``[mesh.convert]``
    penalty coupling does it already (they couple every particle)."""
    ero = mm.spec.erosion
    if (ero is None or ero.to != "particles" or mm.spec.contact is not None
            or (mm.converted is not None and mm.converted.spec.coupling == "penalty")):
        return Built()
    return Built(interactions=[PenaltyCoupling(
        f"{mm.name}_debris", ctx.sph, ctx.meshes[mm.name], stiffness=ero.stiffness,
        alpha=ero.alpha, thickness_factor=ero.thickness_factor, friction=ero.friction,
        stiffness_step=ero.stiffness_step)])


register(Builder("mesh.convert", build_convert, stage=430, mesh=True))
register(Builder("mesh.sublayer", build_sublayer, stage=440, mesh=True))
register(Builder("mesh.contact", build_contact, stage=450, mesh=True))
register(Builder("mesh.erosion", build_debris_contact, stage=460, mesh=True))
