"""Builders of the finite elements: ``[[mesh]]`` (a solid or line part per
mesh), the sub-tables run mesh by mesh (stage 400), their damping and the
``[[wall]]`` tables on solid meshes, and ``[mesh.embed]``."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..deck import DeckError
from ..deck.errors import format_problem
from ..interactions import Wall
from ..interactions.embedded import EmbeddedNodes
from ..interactions.nodal import MassDamping
from ..materials import get_model
from .mesh_model import section_of
from ..parts import SolidSettings
from ..parts.fem import LinePart, solid_part
from .registry import MESH_STAGE, Builder, Built, builders, register

#: the elements of a line mesh, in a message
PLURAL = {"beam": "beams", "truss": "trusses"}


def material_of(deck, k: int):
    """``(model, packed params)`` of the deck's material ``k``."""
    m = deck.material[k]
    model = get_model(m.model)
    return model, model.pack(m.values())


def mesh_part(deck, mm):
    """The solid or line part of one mesh (initial velocity set)."""
    spec = mm.spec
    if mm.element == "solid":
        materials = {int(k): material_of(deck, int(k)) for k in np.unique(mm.mat)}
        settings = SolidSettings(
            integration=spec.integration, hourglass=spec.hourglass,
            hourglass_coefficient=spec.hourglass_coefficient, q1=spec.q1, q2=spec.q2,
            cfl=spec.cfl)
        part = solid_part(mm.name, mm.points, mm.cells, deck.run.dimension, materials,
                          mat=mm.mat, settings=settings)
    else:
        section = section_of(spec)
        model, params = material_of(deck, int(mm.mat[0]))
        if spec.sublayer is not None:  # the elements carry (1 - r) of the bar's mass
            keep = 1.0 - spec.sublayer.mass_ratio
            mat = deck.material[int(mm.mat[0])]
            if spec.sublayer.stiffness in ("split", "axial"):  # ... and of its stiffness
                values = mat.stress_scaled(keep)  # (model checked by build_model)
            else:
                values = dict(mat.values())
            values["density"] *= keep
            params = model.pack(values)
        if mm.element == "beam" and not model.linear_elastic:
            raise DeckError([format_problem(
                f"mesh[{mm.index}] '{mm.name}'.material", f"beams are elastic resultant "
                f"beams; material model '{model.name}' is not elastic",
                "use an elastic material, or element = \"truss\" for an inelastic bar")])
        part = LinePart(mm.name, mm.points, mm.cells, element=mm.element, section=section,
                        material=(model, params), orientation=spec.section.orientation,
                        damping=spec.damping, dt_scale=spec.cfl)
    part.kin.v[:] = np.asarray(spec.velocity, dtype=float)
    return part


def build_mesh_parts(ctx) -> Built:
    """``[[mesh]]``: one part per mesh, in the deck's order."""
    for mm in ctx.model.meshes:
        ctx.meshes[mm.name] = mesh_part(ctx.deck, mm)
    return Built(parts=list(ctx.meshes.values()))


def build_mesh_tables(ctx) -> Built:
    """Each mesh's sub-table builders (``Builder.mesh``), mesh by mesh."""
    out, tables = Built(), builders(mesh=True)  # by their stages, 400-499
    for mm in ctx.model.meshes:
        for b in tables:
            out.extend(b.build(ctx, mm))
    return out


def build_mesh_damping(ctx, mm) -> Built:
    """``[[mesh]] damping`` of a solid mesh (a line part damps itself)."""
    if mm.element != "solid" or mm.spec.damping <= 0.0:
        return Built()
    part = ctx.meshes[mm.name]
    return Built(interactions=[MassDamping(mm.name, part, np.arange(part.kin.n),
                                           mm.spec.damping)])


def build_mesh_walls(ctx, mm) -> Built:
    """``[[wall]]`` on a solid mesh: each wall, named ``<wall>_<mesh>``."""
    if mm.element != "solid":
        return Built()
    part = ctx.meshes[mm.name]
    return Built(interactions=[Wall(replace(spec, name=f"{spec.name}_{mm.name}"), part)
                               for spec in ctx.model.walls])


def build_embedded(ctx) -> Built:
    """``[mesh.embed]``: a bar's nodes moved with the solid mesh around them
    (last of the interactions: they pass on what the bars' nodes were given)."""
    out = Built()
    for mm in ctx.model.meshes:
        if mm.spec.embed is None:
            continue
        host = next(m for m in ctx.model.meshes if m.name == mm.spec.embed)
        where = f"mesh[{mm.index}] '{mm.name}'.embed"
        if host.element != "solid":
            raise DeckError([format_problem(where, f"mesh '{host.name}' is a line of "
                                            f"{PLURAL[host.element]}, not solid elements",
                                            "embed the bar in a [mesh.block] or a file "
                                            "of hex8 / quad4")])
        try:
            out.interactions.append(EmbeddedNodes(f"{mm.name}_embedded",
                                                  ctx.meshes[mm.name],
                                                  ctx.meshes[host.name]))
        except ValueError as exc:
            raise DeckError([format_problem(where, str(exc).split(": ", 1)[-1],
                                            "move the bar into the solid mesh")]) from None
    return out


register(Builder("mesh", build_mesh_parts, stage=110))
register(Builder("mesh.*", build_mesh_tables, stage=MESH_STAGE))
register(Builder("mesh.damping", build_mesh_damping, stage=410, mesh=True))
register(Builder("mesh.wall", build_mesh_walls, stage=420, mesh=True))
register(Builder("mesh.embed", build_embedded, stage=500))
