"""Builders of the conditions on sets: ``[[boundary]]`` (prescribed motion,
non-reflecting faces), ``[[load]]`` (forces, pressures), ``[[blast]]``
(Kingery-Bulmash loads) and ``[run] gravity``.

History names: a boundary's reactions ``<set>_reaction_x|y|z``, a load's
``<set>_force`` (a pressure's ``<set>_pressure`` and ``<set>_force_x|y|z``)
and ``W_<set>``, a blast load ``W_<blast>``, ``<blast>_force_x|y|z`` and
``<blast>_impulse_x|y|z`` (two conditions on one set: ``<set>_2``...).
"""

from __future__ import annotations

from ..deck import DeckError
from ..deck.errors import format_problem
from ..interactions import Gravity
from ..interactions.blast import BlastLoad
from ..interactions.nodal import NodalLoad, PrescribedMotion
from ..interactions.non_reflecting import NonReflectingBoundary
from ..interactions.pressure import PressureLoad
from .mesh_model import pressure_faces, set_faces
from ..state import BC_FIXED
from .registry import Builder, Built, register


def build_boundaries(ctx) -> Built:
    """``[[boundary]]``: prescribed motion of a set (and fixed rotations of beam
    nodes), or a non-reflecting boundary on a solid mesh's faces."""
    out, model = Built(), ctx.model
    for k, bnd in enumerate(ctx.deck.boundary):
        part, idx = ctx.target(bnd.set)
        if bnd.type == "non_reflecting":
            faces, elements = pressure_faces(model.meshes, model.mesh_sets, bnd.set,
                                             f"boundary[{k}].set",
                                             "a non-reflecting boundary")
            out.interactions.append(NonReflectingBoundary(ctx.unique(bnd.set), part,
                                                          faces, elements))
            continue
        value = {"fixed": (0.0, 0.0, 0.0), "velocity": bnd.velocity,
                 "displacement": bnd.displacement}[bnd.type]
        out.interactions.append(PrescribedMotion(
            ctx.unique(bnd.set), part, idx, kind=bnd.type, value=value,
            ramp_time=bnd.ramp_time, shape=bnd.ramp, components=bnd.axes))
        if bnd.rotations == "fixed":
            rot = getattr(part.kin, "rot", None)
            if rot is None:
                raise DeckError([format_problem(
                    f"boundary[{k}].rotations", f"set '{bnd.set}' has no rotational "
                    "degrees of freedom (only beam nodes have)",
                    "remove rotations (solid nodes and particles only translate)")])
            rot.bc[idx] = BC_FIXED
            rot.v[idx] = 0.0
    return out


def build_loads(ctx) -> Built:
    """``[[load]]``: a force on a set's items, or a pressure on a mesh's faces."""
    out, model = Built(), ctx.model
    for k, load in enumerate(ctx.deck.load):
        part, idx = ctx.target(load.set)
        name = ctx.unique(load.set)
        if load.pressure is None:
            out.interactions.append(NodalLoad(name, part, idx, load.force,
                                              ramp_time=load.ramp_time, shape=load.ramp,
                                              curve=load.curve))
            continue
        faces, elements = pressure_faces(model.meshes, model.mesh_sets, load.set,
                                         f"load[{k}].set")
        out.interactions.append(PressureLoad(name, part, faces, elements, load.pressure,
                                             ramp_time=load.ramp_time, shape=load.ramp,
                                             curve=load.curve))
    return out


def build_blasts(ctx) -> Built:
    """``[[blast]]``: the loads on the exposed faces of each set (particle faces,
    or the exterior faces of a solid mesh on the set's nodes)."""
    out, model = Built(), ctx.model
    for k, bl in enumerate(ctx.deck.blast):
        where = f"blast[{k}]"
        part, idx = ctx.target(bl.set)
        faces = elements = None
        if bl.set in model.mesh_sets:
            faces, elements = set_faces(model.meshes, model.mesh_sets, bl.set,
                                        f"{where}.set", "name a set of particles or of a "
                                        "solid mesh's nodes")
        try:
            out.interactions.append(BlastLoad(
                ctx.unique(bl.name or "blast"), part, bl.charge, bl.point, burst=bl.burst,
                time=bl.time, idx=idx, faces=faces, elements=elements,
                turned_away=bl.turned_away))
        except ValueError as exc:
            fix = ("name a set on the surface of a body or mesh" if "no exposed" in str(exc)
                   else "move the charge or choose other faces; closer in, model the "
                        "charge itself (a high_explosive body, docs/examples.md)")
            raise DeckError([format_problem(where, str(exc).split(": ", 1)[-1], fix)]) \
                from None
    return out


def build_gravity(ctx) -> Built:
    """``[run] gravity``: a body load on every part built so far."""
    g = ctx.deck.run.gravity
    if g is None or not any(g):
        return Built()
    return Built(interactions=[Gravity(q, g) for q in ctx.parts])


register(Builder("boundary", build_boundaries, stage=300))
register(Builder("load", build_loads, stage=310))
register(Builder("blast", build_blasts, stage=320))
register(Builder("run.gravity", build_gravity, stage=600))
