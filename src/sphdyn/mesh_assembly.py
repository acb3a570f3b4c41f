"""Deck -> mesh parts and their interactions: boundaries, loads, damping, walls, couplings.

Called by :func:`sphdyn.assembly.build_stepper` with the meshes of
:mod:`sphdyn.mesh_model`. Names in the history: a boundary's reactions
``<set>_reaction_x|y|z``, a load's ``<set>_force`` (a pressure's
``<set>_pressure`` and ``<set>_force_x|y|z``) and ``W_<set>``, a mesh's damping
``E_damping_<mesh>``, a wall on a mesh ``F_wall_<wall>_<mesh>``, a coupling
``F_<mesh>_coupling`` (penalty) or ``F_<mesh>_coupling_x|y|z`` (tied, hybrid),
the sublayer of a bar ``F_<mesh>_sublayer_x|y|z`` (the bond force), the
debris coupling of an eroding mesh ``F_<mesh>_debris``, its erosion
``eroded_<mesh>`` and the rest of :meth:`sphdyn.events.ElementErosion.columns`,
a blast load ``W_<blast>``, ``<blast>_force_x|y|z`` and ``<blast>_impulse_x|y|z``.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .deck import DeckError
from .deck.errors import format_problem
from .events import ElementErosion, ErosionRules
from .interactions import HybridCoupling, PenaltyCoupling, TiedCoupling, Wall
from .interactions.nodal import MassDamping, NodalLoad, PrescribedMotion
from .interactions.blast import BlastLoad
from .interactions.non_reflecting import NonReflectingBoundary
from .interactions.pressure import PressureLoad
from .interactions.embedded import EmbeddedNodes
from .interactions.sublayer import SublayerCoupling
from .materials import get_model
from .mesh_model import MeshModel, pressure_faces, set_faces
from .parts import SolidSettings
from .parts.fem import BeamSection, LinePart, solid_part
from .state import BC_FIXED


def _material(deck, k: int):
    """``(model, packed params)`` of the deck's material ``k``."""
    m = deck.material[k]
    model = get_model(m.model)
    return model, model.pack(m.values())


def section_of(spec) -> BeamSection:
    """The cross-section of a [mesh.line]'s [mesh.section]."""
    sec = spec.section
    return (BeamSection.rectangle(sec.width, sec.height) if sec.shape == "rectangle"
            else BeamSection.circle(sec.diameter))


def mesh_part(deck, mm: MeshModel):
    """The solid or line part of one mesh (initial velocity set)."""
    spec = mm.spec
    if mm.element == "solid":
        materials = {int(k): _material(deck, int(k)) for k in np.unique(mm.mat)}
        settings = SolidSettings(
            integration=spec.integration, hourglass=spec.hourglass,
            hourglass_coefficient=spec.hourglass_coefficient, q1=spec.q1, q2=spec.q2,
            cfl=spec.cfl)
        part = solid_part(mm.name, mm.points, mm.cells, deck.run.dimension, materials,
                          mat=mm.mat, settings=settings)
    else:
        section = section_of(spec)
        model, params = _material(deck, int(mm.mat[0]))
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


def _unique(name: str, taken: set) -> str:
    """``name``, or ``name_2``, ``name_3``... if taken (two conditions on one set)."""
    out, k = name, 1
    while out in taken:
        k += 1
        out = f"{name}_{k}"
    taken.add(out)
    return out


def _target(model, sph_part, meshes: dict, set_name: str):
    """The part and the indices (n,) of a [[set]]."""
    if set_name in model.mesh_sets:
        mesh, idx = model.mesh_sets[set_name]
        return meshes[mesh], idx
    return sph_part, model.sets[set_name]


#: the elements of a line mesh, in a message
_PLURAL = {"beam": "beams", "truss": "trusses"}


def mesh_interactions(deck, model, sph_part, meshes: dict) -> list:
    """Prescribed motions, loads, damping, walls on meshes and the couplings."""
    out, taken = [], set()
    for k, bnd in enumerate(deck.boundary):
        part, idx = _target(model, sph_part, meshes, bnd.set)
        if bnd.type == "non_reflecting":
            faces, elements = pressure_faces(model.meshes, model.mesh_sets, bnd.set,
                                             f"boundary[{k}].set",
                                             "a non-reflecting boundary")
            out.append(NonReflectingBoundary(_unique(bnd.set, taken), part, faces,
                                             elements))
            continue
        value = {"fixed": (0.0, 0.0, 0.0), "velocity": bnd.velocity,
                 "displacement": bnd.displacement}[bnd.type]
        out.append(PrescribedMotion(_unique(bnd.set, taken), part, idx, kind=bnd.type,
                                    value=value, ramp_time=bnd.ramp_time, shape=bnd.ramp,
                                    components=bnd.axes))
        if bnd.rotations == "fixed":
            rot = getattr(part.kin, "rot", None)
            if rot is None:
                raise DeckError([format_problem(
                    f"boundary[{k}].rotations", f"set '{bnd.set}' has no rotational "
                    "degrees of freedom (only beam nodes have)",
                    "remove rotations (solid nodes and particles only translate)")])
            rot.bc[idx] = BC_FIXED
            rot.v[idx] = 0.0
    for k, load in enumerate(deck.load):
        part, idx = _target(model, sph_part, meshes, load.set)
        name = _unique(load.set, taken)
        if load.pressure is None:
            out.append(NodalLoad(name, part, idx, load.force, ramp_time=load.ramp_time,
                                 shape=load.ramp, curve=load.curve))
            continue
        faces, elements = pressure_faces(model.meshes, model.mesh_sets, load.set,
                                         f"load[{k}].set")
        out.append(PressureLoad(name, part, faces, elements, load.pressure,
                                ramp_time=load.ramp_time, shape=load.ramp,
                                curve=load.curve))
    out += blast_loads(deck, model, sph_part, meshes, taken)
    for b, body in enumerate(deck.body):
        if body.damping > 0.0:
            out.append(MassDamping(body.name, sph_part,
                                   np.flatnonzero(sph_part.p.body == b), body.damping))
    for mm in model.meshes:
        part = meshes[mm.name]
        if mm.element == "solid":
            if mm.spec.damping > 0.0:
                out.append(MassDamping(mm.name, part, np.arange(part.kin.n),
                                       mm.spec.damping))
            out += [Wall(replace(spec, name=f"{spec.name}_{mm.name}"), part)
                    for spec in model.walls]
        if mm.converted is not None:
            rows = np.flatnonzero(sph_part.p.body == model.body_names.index(mm.name))
            coupling = _coupling(mm, sph_part, part, rows)
            if mm.spec.damping > 0.0:  # the converted particles are damped alike
                slaves = np.concatenate([np.zeros(0, np.int64)]
                                        + [getattr(c, "slaves", np.zeros(0, np.int64))
                                           for c in coupling])
                out.append(MassDamping(f"{mm.name}_particles", sph_part,
                                       np.setdiff1d(rows, slaves), mm.spec.damping))
            out += coupling  # after every other interaction on the particles
        if mm.spec.sublayer is not None:
            own = model.body_names.index(f"{mm.name}_sublayer")
            rows = np.flatnonzero(sph_part.p.body == own)
            out.append(SublayerCoupling(f"{mm.name}_sublayer", sph_part, part, rows,
                                        np.arange(part.kin.n)))
        ero, con = mm.spec.erosion, mm.spec.contact
        if con is not None:
            keys = dict(stiffness=con.stiffness, alpha=con.alpha,
                        thickness_factor=con.thickness_factor, friction=con.friction,
                        stiffness_step=con.stiffness_step)
            if sph_part is not None:  # a model of meshes only has no particles
                out.append(PenaltyCoupling(f"{mm.name}_contact", sph_part, part, **keys))
            for slave in _contact_meshes(model, mm):
                out.append(PenaltyCoupling(f"{mm.name}_contact_{slave}", meshes[slave],
                                           part, **keys))
        elif ero is not None and ero.to == "particles" and not (
                mm.converted is not None and mm.converted.spec.coupling == "penalty"):
            # the debris meets the remaining elements by penalty ([mesh.contact]
            # or a [mesh.convert] penalty coupling does it already: they couple
            # every particle)
            out.append(PenaltyCoupling(f"{mm.name}_debris", sph_part, part,
                                       stiffness=ero.stiffness, alpha=ero.alpha,
                                       thickness_factor=ero.thickness_factor,
                                       friction=ero.friction,
                                       stiffness_step=ero.stiffness_step))
    for mm in model.meshes:  # last: they pass on what the bars' nodes were given
        if mm.spec.embed is None:
            continue
        host = next(m for m in model.meshes if m.name == mm.spec.embed)
        where = f"mesh[{mm.index}] '{mm.name}'.embed"
        if host.element != "solid":
            raise DeckError([format_problem(where, f"mesh '{host.name}' is a line of "
                                            f"{_PLURAL[host.element]}, not solid elements",
                                            "embed the bar in a [mesh.block] or a file "
                                            "of hex8 / quad4")])
        try:
            out.append(EmbeddedNodes(f"{mm.name}_embedded", meshes[mm.name],
                                     meshes[host.name]))
        except ValueError as exc:
            raise DeckError([format_problem(where, str(exc).split(": ", 1)[-1],
                                            "move the bar into the solid mesh")]) from None
    return out


def _contact_meshes(model, mm) -> list[str]:
    """The solid meshes of ``[mesh.contact] meshes`` (their nodes are slaves of
    ``mm``'s faces); a line mesh or ``mm`` itself is a deck error."""
    kinds = {m.name: m.element for m in model.meshes}
    where = f"mesh[{mm.index}] '{mm.name}'.contact.meshes"
    for slave in mm.spec.contact.meshes:
        if slave == mm.name:
            raise DeckError([format_problem(where, f"mesh '{slave}' is this mesh: a "
                                            "mesh does not contact its own faces",
                                            "name the other mesh that meets these faces")])
        if kinds[slave] != "solid":
            raise DeckError([format_problem(where, f"mesh '{slave}' is a line of "
                                            f"{_PLURAL[kinds[slave]]}, not solid elements",
                                            "list solid meshes only (a bar inside a solid "
                                            "mesh: embed)")])
    return list(mm.spec.contact.meshes)


def blast_loads(deck, model, sph_part, meshes: dict, taken: set) -> list:
    """The [[blast]] loads: the exposed faces of each set (particle faces, or
    the exterior faces of a solid mesh on the set's nodes)."""
    out = []
    for k, bl in enumerate(deck.blast):
        where = f"blast[{k}]"
        part, idx = _target(model, sph_part, meshes, bl.set)
        faces = elements = None
        if bl.set in model.mesh_sets:
            faces, elements = set_faces(model.meshes, model.mesh_sets, bl.set,
                                        f"{where}.set", "name a set of particles or of a "
                                        "solid mesh's nodes")
        try:
            out.append(BlastLoad(_unique(bl.name or "blast", taken), part, bl.charge,
                                 bl.point, burst=bl.burst, time=bl.time, idx=idx,
                                 faces=faces, elements=elements,
                                 turned_away=bl.turned_away))
        except ValueError as exc:
            fix = ("name a set on the surface of a body or mesh" if "no exposed" in str(exc)
                   else "move the charge or choose other faces; closer in, model the "
                        "charge itself (a high_explosive body, docs/examples.md)")
            raise DeckError([format_problem(where, str(exc).split(": ", 1)[-1], fix)]) \
                from None
    return out


def erosion_events(deck, model, sph_part, meshes: dict) -> list:
    """The :class:`~sphdyn.events.ElementErosion` of every mesh with [mesh.erosion],
    with its materials' [material.erosion] rules."""
    out = []
    for mm in model.meshes:
        ero = mm.spec.erosion
        if ero is None:
            continue
        part, rules = meshes[mm.name], {}
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
        to_particles = ero.to == "particles"
        out.append(ElementErosion(
            f"erosion_{mm.name}", part, rules, to=ero.to,
            per_element=ero.particles_per_element, sph=sph_part if to_particles else None,
            body=(model.body_names.index(f"{mm.name}_debris") if to_particles else 0),
            h_factor=deck.sph.h_factor, every=ero.every))
    return out


def _coupling(mm: MeshModel, sph_part, part, rows) -> list:
    """The coupling of a mesh's converted particles (``rows``, (k,), then the
    hybrid layer's) with its remaining elements; its ``slaves`` (particles the
    mesh moves) are left out of the particles' damping."""
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
