"""Deck -> meshes: the [[mesh]] tables as node coordinates, connectivity and sets.

With :mod:`sphdyn.build.model` (particles) and :mod:`sphdyn.build` (parts and
interactions) the only place that reads the deck's meshes. Every problem is
found here, before a part is made or a file written, and reported as a
:class:`~sphdyn.deck.DeckError` line ``mesh[k]...: <what>. Fix: <what>``
(exit status 2 on the command line): an unreadable file, an unknown group,
inverted or degenerate elements (named by element id), a conversion region
without elements, an empty node set, a set with no face to carry a pressure.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..deck import DeckError
from ..deck.errors import format_problem
from ..geometry import select
from ..geometry.convert import element_centroids, elements_to_particles, hybrid_points
from ..geometry.mesh import MeshData, check_elements
from ..geometry.mesh_blocks import block_mesh, polyline_mesh, prism_mesh
from ..geometry.mesh_files import read_mesh
from ..interactions.penalty_geometry import exterior_faces, on_nodes
from ..parts.fem import BeamSection

#: Element kind of a solid mesh by dimension.
SOLID_KIND = {3: "hex8", 2: "quad4"}


@dataclass
class Converted:
    """Particles made of a mesh's converted elements (one per element).

    ``x`` (k, 3) centroids [m], ``vol`` (k,) volumes [m^d], ``mat`` (k,)
    deck material indices; ``spec``: the deck's [mesh.convert]. With the
    hybrid coupling, ``hybrid``: the particles at the hybrid layer's
    integration points, appended to the body after the converted ones.
    """

    x: np.ndarray
    vol: np.ndarray
    mat: np.ndarray
    spec: object
    hybrid: "HybridLayer | None" = None


@dataclass
class HybridLayer:
    """Integration points of the hybrid elements (:func:`~sphdyn.geometry.convert.hybrid_points`):
    ``elem`` (H,) in the remaining mesh, ``x`` (H, 3) [m], ``vol`` (H,) [m^d],
    ``xi`` (H, d) natural coordinates, ``mat`` (H,) deck material indices."""

    elem: np.ndarray
    x: np.ndarray
    vol: np.ndarray
    xi: np.ndarray
    mat: np.ndarray


@dataclass
class MeshModel:
    """One [[mesh]] after reading, checking and conversion.

    Attributes
    ----------
    name, index : the deck's name and table index.
    element : ``"solid"``, ``"beam"`` or ``"truss"``.
    kind : ``"hex8"``, ``"quad4"`` or ``"line2"``.
    points : (N, 3) [m] the nodes (of the remaining mesh after a conversion).
    cells : (E, nen) int64 connectivity.
    mat : (E,) int32 deck material index of every element.
    node_sets : dict name -> (n,) int64, the mesh file's node sets (renumbered).
    spec : the deck's Mesh table.
    converted : the particles made of a [mesh.convert] region, or None.
    """

    name: str
    index: int
    element: str
    kind: str
    points: np.ndarray
    cells: np.ndarray
    mat: np.ndarray
    spec: object
    node_sets: dict = field(default_factory=dict)
    element_ids: np.ndarray | None = None
    converted: Converted | None = None


def _read(spec, where: str, dim: int) -> MeshData:
    """The mesh of one [[mesh]] table (generated or read); DeckError if unreadable."""
    if spec.block is not None:
        b = spec.block
        return block_mesh(b.lo, b.hi, b.divisions, dim, b.axis_grading)
    if spec.prism is not None:
        m = spec.prism
        return prism_mesh(m.points, m.element_size, dim, m.axis, m.base, m.length)
    if spec.line is not None:
        ln = spec.line
        return polyline_mesh(ln.corners, ln.counts, ln.closed, ln.repeat,
                             ln.step if ln.step is not None else (0.0, 0.0, 0.0))
    try:
        mesh = read_mesh(spec.file, dim, kind=SOLID_KIND[dim])
    except (ValueError, OSError, KeyError, IndexError) as exc:
        raise DeckError([format_problem(
            f"{where}.file", f"the mesh file cannot be used ({exc})",
            f"give a Gmsh .msh (2.2 or 4.1) or Abaqus .inp file with "
            f"{SOLID_KIND[dim]} elements")]) from None
    if spec.length_unit != 1.0:
        mesh.points *= spec.length_unit
    mesh.points += np.asarray(spec.translate, dtype=float)[:mesh.points.shape[1]]
    return mesh


def _materials(spec, mesh: MeshData, where: str, mat_index: dict) -> np.ndarray:
    """(E,) deck material index of every element: groups first, then the mesh's."""
    mat = np.full(mesh.n_elements, -1, np.int32)
    for j, g in enumerate(spec.group):
        if g.name not in mesh.element_sets:
            known = ", ".join(sorted(mesh.element_sets)) or "none"
            raise DeckError([format_problem(
                f"{where}.group[{j}].name", f"the file has no element group '{g.name}'",
                f"use one of its groups: {known} (names are case-sensitive)")])
        mat[mesh.element_sets[g.name]] = mat_index[g.material]
    if spec.material is not None:
        mat[mat < 0] = mat_index[spec.material]
    missing = np.flatnonzero(mat < 0)
    if missing.size:
        raise DeckError([format_problem(
            f"{where}.material", f"{missing.size} element(s) are in no [[mesh.group]] "
            f"(ids {mesh.element_ids[missing[:10]].tolist()})",
            "add material = \"<name>\" for the elements outside the groups")])
    return mat


def _convert(spec, mesh: MeshData, mat: np.ndarray, where: str, dim: int):
    """Split a mesh by [mesh.convert]: (the remaining mesh, its materials, Converted)."""
    conv = spec.convert
    centroids, _ = element_centroids(mesh.points, mesh.cells, mesh.kind)
    chosen = select(centroids, conv.region.model_dump(), dim)
    if chosen.size == 0:
        raise DeckError([format_problem(
            f"{where}.convert.region", "no element centroid lies in the region",
            "enlarge the region so that it holds the elements to convert")])
    if chosen.size == mesh.n_elements and conv.coupling != "none":
        raise DeckError([format_problem(
            f"{where}.convert.region", "every element lies in the region, so nothing "
            f"is left to couple to (coupling = \"{conv.coupling}\")",
            "shrink the region, or set coupling = \"none\"")])
    mask = np.zeros(mesh.n_elements, bool)
    mask[chosen] = True
    x, vol, rest, kept = elements_to_particles(mesh.points, mesh.cells, mesh.kind, mask)
    renumber = np.full(mesh.n_nodes, -1, np.int64)
    renumber[kept] = np.arange(kept.size)
    sets = {k: renumber[v][renumber[v] >= 0] for k, v in mesh.node_sets.items()}
    remaining = MeshData(mesh.points[kept], rest, mesh.kind, node_sets=sets,
                         element_ids=mesh.element_ids[~mask], node_ids=mesh.node_ids[kept],
                         source=mesh.source)
    converted = Converted(x, vol, mat[mask].astype(np.int32), conv)
    if conv.coupling == "hybrid":
        elem, hx, hvol, hxi = hybrid_points(mesh.points, mesh.cells, mesh.kind, mask,
                                            spec.integration == "one_point")
        if elem.size == 0:
            raise DeckError([format_problem(
                f"{where}.convert.region", "no remaining element shares a face with a "
                "converted one, so the hybrid coupling has no transition layer",
                "make the converted region touch the rest of the mesh")])
        converted.hybrid = HybridLayer(elem, hx, hvol, hxi,
                                       mat[~mask][elem].astype(np.int32))
    return remaining, mat[~mask], converted


def converted_count(spec, k: int, dim: int) -> int:
    """Particles the [mesh.convert] of the [[mesh]] ``spec`` (table ``k``)
    makes: one per converted element and, with the hybrid coupling, one per
    integration point of the transition layer (as :func:`build_meshes`
    makes them; the same DeckErrors)."""
    where = f"mesh[{k}] '{spec.name}'"
    mesh = _read(spec, where, dim)
    _, _, conv = _convert(spec, mesh, np.zeros(mesh.n_elements, np.int32), where, dim)
    return conv.x.shape[0] + (conv.hybrid.x.shape[0] if conv.hybrid is not None else 0)


def section_of(spec) -> BeamSection:
    """The cross-section of a [mesh.line]'s [mesh.section]."""
    sec = spec.section
    return (BeamSection.rectangle(sec.width, sec.height) if sec.shape == "rectangle"
            else BeamSection.circle(sec.diameter))

def build_meshes(deck) -> list[MeshModel]:
    """Every [[mesh]] of a validated deck, read, checked and converted.

    Raises :class:`~sphdyn.deck.DeckError` naming the table and the fix.
    """
    dim = deck.run.dimension
    mat_index = {m.name: k for k, m in enumerate(deck.material)}
    out = []
    for k, spec in enumerate(deck.mesh):
        where = f"mesh[{k}] '{spec.name}'"
        mesh = _read(spec, where, dim)
        try:
            check_elements(mesh)
        except ValueError as exc:
            raise DeckError([format_problem(
                where, str(exc), "fix the mesh (the ids are the file's element "
                "numbers, 1-based positions for generated meshes)")]) from None
        mat = _materials(spec, mesh, where, mat_index)
        converted = None
        if spec.convert is not None:
            mesh, mat, converted = _convert(spec, mesh, mat, where, dim)
        element = "solid" if spec.line is None else spec.element
        out.append(MeshModel(
            name=spec.name, index=k, element=element, kind=mesh.kind,
            points=mesh.points, cells=mesh.cells, mat=mat, spec=spec,
            node_sets=mesh.node_sets, element_ids=mesh.element_ids, converted=converted))
    return out


def mesh_node_set(meshes: list[MeshModel], s, k: int, dim: int) -> tuple[MeshModel, np.ndarray]:
    """The mesh and node indices (n,) of a [[set]] with ``mesh``; DeckError if empty."""
    mm = next(m for m in meshes if m.name == s.mesh)
    idx = np.arange(mm.points.shape[0], dtype=np.int64)
    if s.group is not None:
        if s.group not in mm.node_sets:
            known = ", ".join(sorted(mm.node_sets)) or "none"
            raise DeckError([format_problem(
                f"set[{k}] '{s.name}'.group", f"mesh '{mm.name}' has no group '{s.group}'",
                f"use one of its groups: {known} (names are case-sensitive)")])
        idx = mm.node_sets[s.group]
    if s.region is not None:
        idx = idx[select(mm.points[idx], s.region.model_dump(), dim)]
    if idx.size == 0:
        raise DeckError([format_problem(
            f"set[{k}] '{s.name}'", f"the set holds no node of mesh '{mm.name}'",
            "enlarge the region (nodes are selected by their initial position; "
            "a box must contain them, edges included) or check the group")])
    return mm, idx.astype(np.int64)


def set_faces(meshes: list[MeshModel], mesh_sets: dict, set_name: str, where: str,
              fix: str) -> tuple[np.ndarray, np.ndarray]:
    """The exterior faces (F, 4) or edges (F, 2) of a solid mesh whose nodes all
    lie in the mesh node set ``set_name`` (``mesh_sets``: name -> (mesh, nodes)),
    outward node order, and their elements (F,); F may be 0. DeckError naming
    ``where`` (with ``fix``) if the set holds nodes of a line of beams or trusses."""
    mesh, idx = mesh_sets[set_name]
    mm = next(m for m in meshes if m.name == mesh)
    if mm.element != "solid":
        raise DeckError([format_problem(
            where, f"set '{set_name}' holds nodes of the {mm.element} line '{mm.name}', "
                   "which has no faces", fix)])
    faces, elements = exterior_faces(mm.cells, with_elements=True)
    keep = on_nodes(faces, idx)
    return faces[keep], elements[keep]


def pressure_faces(meshes: list[MeshModel], mesh_sets: dict, set_name: str,
                   where: str, what: str = "a pressure") -> tuple[np.ndarray, np.ndarray]:
    """The faces a pressure (or, ``what``, a non-reflecting boundary) on the set
    ``set_name`` acts on (:func:`set_faces`); DeckError naming ``where`` if the
    set holds particles, nodes of a line, or no whole exterior face."""
    # what else the user may give instead (a pressure: a force shared by the items)
    instead = ((", or give force = [...] (shared by the particles)",
                ", or give force = [...] (shared by the nodes)") if what == "a pressure"
               else ("", ""))
    if set_name not in mesh_sets:
        raise DeckError([format_problem(
            where, f"set '{set_name}' holds particles; {what} acts on the faces of a "
                   "solid mesh", "name a [[set]] with mesh = \"<name>\" whose nodes "
                   "cover the surface" + instead[0])])
    faces, elements = set_faces(meshes, mesh_sets, set_name, where,
                                "name a set of a solid mesh's nodes" + instead[1])
    if faces.shape[0] == 0:
        mesh, idx = mesh_sets[set_name]
        face = "edge" if faces.shape[1] == 2 else "face"
        raise DeckError([format_problem(
            where, f"set '{set_name}' holds {idx.size} node(s) of mesh '{mesh}' but no "
                   f"exterior {face} of the mesh has all its nodes in the set",
            f"select whole {face}s: a region around the surface that contains "
            f"every node of its {face}s (or a group of the mesh file that does)")])
    return faces, elements
