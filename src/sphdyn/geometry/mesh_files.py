"""Meshes read from files: Gmsh ``.msh`` (formats 2.2 and 4.1) and Abaqus
``.inp``, into a :class:`~sphdyn.geometry.mesh.MeshData` whose errors name the
file's own node and element ids.

Files are read with :mod:`meshio`'s format readers (``meshio.gmsh.read``,
``meshio.abaqus.read``; not ``meshio.read``, which ends the process on a read
error). meshio 5.3 does not know the Abaqus plane-strain quads (``CPE4``,
``CPE4R``, ...); this module registers them with meshio's Abaqus reader as
``quad`` when it is imported.
"""

from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np

from .lattice import _check_dim
from .mesh import _FROM_MESHIO, _KINDS_IN, TO_MESHIO, MeshData, element_jacobians

__all__ = ["read_mesh"]

# file extension -> (meshio format, label, reader)
_FORMATS = {".msh": ("gmsh", "Gmsh", meshio.gmsh.read),
            ".inp": ("abaqus", "Abaqus", meshio.abaqus.read)}


def _register_abaqus_plane_strain() -> None:
    """Teach meshio's Abaqus reader the 4-node plane-strain elements (as quad)."""
    try:
        from meshio.abaqus import _abaqus
    except ImportError:  # pragma: no cover - another meshio layout
        return
    for name in ("CPE4", "CPE4R", "CPE4H", "CPE4RH", "CPE4I", "CPE4IH"):
        _abaqus.abaqus_to_meshio_type.setdefault(name, "quad")


_register_abaqus_plane_strain()


def _gmsh_ids(text: str):
    """Node and element tags of an ASCII MSH 2.2 / 4.1 file, in file order.

    Returns ``(node_tags, element_tags)`` or None (binary or other version).
    """
    lines = [s.strip() for s in text.splitlines()]
    head = lines[lines.index("$MeshFormat") + 1].split()
    if head[1] != "0":
        return None
    version = head[0].split(".")[0]
    i, j = lines.index("$Nodes"), lines.index("$EndNodes")
    k, m = lines.index("$Elements"), lines.index("$EndElements")
    if version == "2":
        nodes = [int(s.split()[0]) for s in lines[i + 2: j]]
        elements = [int(s.split()[0]) for s in lines[k + 2: m]]
    elif head[0] in ("4", "4.1"):
        tok = " ".join(lines[i + 1: j]).split()
        nodes, p = [], 4
        for _ in range(int(tok[0])):    # entityDim entityTag parametric numNodes
            nb = int(tok[p + 3])
            nodes += [int(t) for t in tok[p + 4: p + 4 + nb]]
            p += 4 + 4 * nb             # the tags, then x y z per node
        elements, q = [], k + 2
        while q < m:                    # entityDim entityTag type numElements
            nb = int(lines[q].split()[3])
            elements += [int(s.split()[0]) for s in lines[q + 1: q + 1 + nb]]
            q += 1 + nb
    else:
        return None
    return np.array(nodes, dtype=np.int64), np.array(elements, dtype=np.int64)


def _abaqus_scan(text: str, label: str) -> dict:
    """A pass over an Abaqus file that refuses what meshio 5.3 would misread
    and records what it drops.

    Returns a dict: ``nodes`` node ids in meshio's order, ``blocks`` the
    integers of each ``*ELEMENT`` block (both None if a data line does not
    parse; meshio then reports the file), ``elset_of_block`` each
    ``*ELEMENT`` block's ``ELSET=`` value, ``elsets`` the names ``*ELSET``
    defines.
    """
    nodes, blocks, params, elsets = [], [], [], set()
    mode, name, n_node_blocks, ok = None, None, 0, True
    for line in text.splitlines():
        s = line.strip()
        if line.startswith("*"):
            words = s.split(",")
            mode = None if s.startswith("**") else words[0].replace("*", "").strip().upper()
            opts = {k.strip().upper(): v.strip()
                    for k, _, v in (w.partition("=") for w in words[1:])}
            if mode == "NODE":
                n_node_blocks += 1
                nodes = []
            elif mode == "ELEMENT":
                blocks.append([])
                params.append(opts.get("ELSET"))
            elif mode in ("NSET", "ELSET"):
                name = opts.get(mode)
                if mode == "ELSET":
                    elsets.add(name)
            continue
        if not s or mode is None:
            continue
        first = s.split(",")[0]
        if mode in ("NSET", "ELSET") and not first.isnumeric():
            raise ValueError(f"{label}: *{mode} {name} lists a set by name ({first}); the "
                             "reader (meshio) does not resolve set names, so list the ids instead")
        try:
            if mode == "NODE":
                nodes.append(int(first))
            elif mode == "ELEMENT":
                blocks[-1] += [int(v) for v in s.split(",") if v.strip()]
        except ValueError:
            ok = False
    if n_node_blocks > 1:
        raise ValueError(f"{label}: {n_node_blocks} *NODE blocks; the reader (meshio) keeps "
                         "only the last one, so merge all nodes into a single *NODE block")
    return {"nodes": np.array(nodes, dtype=np.int64) if ok else None,
            "blocks": blocks if ok else None, "elset_of_block": params, "elsets": elsets}


def _file_ids(text: str, raw, abaqus: dict | None):
    """(node_ids, element_ids over all meshio blocks) or None if not recoverable."""
    sizes = [len(b) for b in raw.cells]
    if abaqus is None:
        ids = _gmsh_ids(text)
        if ids is None:
            return None
        nodes, elements = ids
    else:
        nodes, blocks = abaqus["nodes"], abaqus["blocks"]
        if blocks is None or len(blocks) != len(raw.cells):
            return None
        parts = []
        for ints, b in zip(blocks, raw.cells):
            stride = b.data.shape[1] + 1
            if len(ints) != len(b) * stride:
                return None
            parts.append(np.array(ints[::stride], dtype=np.int64))
        elements = np.concatenate(parts) if parts else np.zeros(0, np.int64)
    if nodes.size != len(raw.points) or elements.size != sum(sizes):
        return None
    return nodes, elements


def _plain(v):
    """A numpy scalar as a plain Python value (for messages)."""
    return v.item() if isinstance(v, np.generic) else v


def _holdings(raw) -> str:
    counts: dict[str, int] = {}
    for b in raw.cells:
        counts[b.type] = counts.get(b.type, 0) + len(b)
    return ", ".join(f"{n} {t}" for t, n in counts.items()) or "no cells"


def _choose_kind(raw, dim: int, kind, label: str) -> str:
    allowed = _KINDS_IN[dim]
    supported = ", ".join(f"{TO_MESHIO[k]} ({k})" for k in allowed)
    present = {}
    for b in raw.cells:
        k = _FROM_MESHIO.get(b.type)
        if k in allowed and len(b):
            present[k] = present.get(k, 0) + len(b)
    if kind is not None:
        if kind not in allowed:
            raise ValueError(f"{label}: kind must be one of {list(allowed)} in {dim}D, "
                             f"got {kind!r}")
        if kind not in present:
            raise ValueError(f"{label}: no {TO_MESHIO[kind]} ({kind}) elements; the file holds "
                             f"{_holdings(raw)}")
        return kind
    if not present:
        raise ValueError(f"{label}: no elements of a supported kind in {dim}D ({supported}); "
                         f"the file holds {_holdings(raw)}; mesh with those element types "
                         "(linear, all-hexahedral or all-quad meshes)")
    if len(present) > 1:
        listing = ", ".join(f"{n} {k}" for k, n in present.items())
        raise ValueError(f"{label}: several supported element kinds ({listing}); say which one "
                         f"to read with kind= (one of {list(present)}); the groups of the "
                         "others become node sets")
    return next(iter(present))


def _groups(raw, label: str) -> dict[str, list[np.ndarray]]:
    """Named groups as per-block local element indices (meshio cell_sets, or
    Gmsh physical tags + names)."""
    nb = len(raw.cells)
    groups = {}
    for name, per_block in (raw.cell_sets or {}).items():
        if name.startswith("gmsh:"):
            continue
        arrays = [np.zeros(0, np.int64)] * nb
        try:
            for b, a in enumerate(list(per_block)[:nb]):
                if a is not None:
                    arrays[b] = np.asarray(a, dtype=np.int64).reshape(-1)
        except (TypeError, ValueError):
            raise ValueError(f"{label}: set {name!r} could not be interpreted; list its element "
                             "ids explicitly") from None
        groups[name] = arrays
    physical = (raw.cell_data or {}).get("gmsh:physical")
    if physical is not None:
        for name, (tag, gdim) in ((k, v[:2]) for k, v in (raw.field_data or {}).items()):
            if name not in groups:
                groups[name] = [np.flatnonzero(np.asarray(t) == tag) if b.dim == gdim
                                else np.zeros(0, np.int64)
                                for b, t in zip(raw.cells, physical)]
    return groups


def _merge_repeats(cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Elements with the same nodes, kept once.

    Returns ``order`` (the rows kept, first occurrences in file order) and
    ``elem_map`` (E,): old row -> index into ``order``.
    """
    _, first, inverse = np.unique(np.sort(cells, axis=1), axis=0, return_index=True,
                                  return_inverse=True)
    rank = np.empty(first.size, np.int64)
    rank[np.argsort(first)] = np.arange(first.size)
    return np.sort(first), rank[inverse.reshape(-1)]


def read_mesh(path, dim: int, kind: str | None = None) -> MeshData:
    """Read a finite-element mesh from a Gmsh ``.msh`` or Abaqus ``.inp`` file.

    Gmsh MSH 2.2 and 4.1 (ASCII or binary) and Abaqus input files are read
    with meshio's readers. Both formats (and meshio) store the linear
    hexahedron, quadrilateral and line in VTK node order, so the connectivity
    is used as is; in 2D, quads numbered clockwise (a surface whose normal is
    -z) are renumbered counter-clockwise, so that every valid element has
    positive Jacobians. Call :func:`check_elements` on the result to refuse
    inverted or degenerate elements.

    Parameters
    ----------
    path : str or path-like
        The mesh file; its extension (``.msh``, ``.inp``) selects the format.
    dim : {2, 3}
        Spatial dimension. In 2D all nodes must lie in one plane z = const
        (to ``1e-6`` times the x-y extent); the mesh is projected to z = 0.
    kind : {"hex8", "line2"} in 3D, {"quad4", "line2"} in 2D, optional
        Which elements to keep (meshio types hexahedron, quad, line). By
        default the single supported kind present; with several present the
        caller must choose.

    Returns
    -------
    MeshData
        The kept elements and only the nodes they use (renumbered 0..N-1 in
        file order). ``node_ids`` / ``element_ids`` are the file's node and
        element numbers (Gmsh tags, Abaqus ids) for ASCII files; for binary
        Gmsh files, or Abaqus files with ``*INCLUDE``, the 1-based positions
        in the file. Sets:

        * every named group (Gmsh physical group with a name in
          ``$PhysicalNames``; Abaqus ``ELSET``) with elements of the kept
          kind becomes an element set, and the node set of its nodes under
          the same name;
        * groups of other element types (e.g. Gmsh physical surfaces of a hex
          mesh, which mark boundary faces) become node sets of their nodes;
        * Abaqus ``NSET`` become node sets (taking precedence over a node set
          derived from an element group of the same name);
        * ``"all"`` (element and node set), unless the file defines it.

        Node sets hold only nodes of the kept elements; sets left empty are
        dropped. Elements listed twice with the same nodes (MSH 2.2 repeats
        an element for each physical group it belongs to) are kept once,
        in all their groups.

    Raises
    ------
    ValueError
        Missing or unreadable file, unsupported extension, no elements of a
        supported kind, several kinds and no ``kind``, a non-planar 2D mesh.
    """
    dim = _check_dim(dim)
    path = Path(path)
    label = f"mesh file '{path}'"
    fmt = _FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise ValueError(f"{label}: unsupported extension {path.suffix!r}; use a Gmsh .msh "
                         "or an Abaqus .inp file")
    if not path.is_file():
        raise ValueError(f"{label}: no such file; check the path (relative paths are "
                         "relative to the deck)")
    fmt, fmt_label, reader = fmt
    text = path.read_bytes().decode("latin-1")
    abaqus = _abaqus_scan(text, label) if fmt == "abaqus" else None
    try:
        raw = reader(path)
    except Exception as exc:  # meshio raises ReadError, ValueError, KeyError, ...
        if isinstance(exc, KeyError) and exc.args:
            detail = f"id {_plain(exc.args[0])} is used but not defined"
        else:
            detail = type(exc).__name__ + (f": {exc}" if str(exc) else "")
        want = ("a complete Gmsh MSH 2.2 or 4.1 file" if fmt == "gmsh" else
                "a complete Abaqus input file (*NODE before *ELEMENT, every node defined)")
        raise ValueError(f"{label}: cannot read it as {fmt_label} mesh ({detail}); check "
                         f"that it is {want}") from exc
    kind = _choose_kind(raw, dim, kind, label)

    try:
        ids = _file_ids(text, raw, abaqus)
    except (ValueError, IndexError):
        ids = None
    n_raw = len(raw.points)
    if ids is None:
        ids = (np.arange(1, n_raw + 1), np.arange(1, sum(len(b) for b in raw.cells) + 1))
    starts = np.cumsum([0] + [len(b) for b in raw.cells])
    points = np.zeros((n_raw, 3))
    raw_points = np.asarray(raw.points, dtype=np.float64).reshape(n_raw, -1)
    points[:, :raw_points.shape[1]] = raw_points[:, :3]

    keep = [b for b, blk in enumerate(raw.cells) if _FROM_MESHIO.get(blk.type) == kind]
    cells = np.concatenate([np.asarray(raw.cells[b].data, dtype=np.int64) for b in keep])
    element_ids = np.concatenate([ids[1][starts[b]:starts[b + 1]] for b in keep])

    order, elem_map = _merge_repeats(cells)
    cells, element_ids = cells[order], element_ids[order]

    # drop unused nodes, renumber in file order
    used = np.unique(cells)
    node_map = np.full(n_raw, -1, np.int64)
    node_map[used] = np.arange(used.size)
    cells = node_map[cells]
    points, node_ids = points[used], ids[0][used]

    if dim == 2:
        z = points[:, 2]
        tol = 1e-6 * max(np.ptp(points[:, 0]), np.ptp(points[:, 1]), np.finfo(float).tiny)
        z_mid = np.median(z)
        worst = int(np.argmax(np.abs(z - z_mid)))
        if abs(z[worst] - z_mid) > tol:
            raise ValueError(f"{label}: a 2D mesh must lie in a plane z = const, but node "
                             f"{node_ids[worst]} has z = {z[worst]:.6g} (median {z_mid:.6g}); "
                             "mesh in the x-y plane or read it with dim=3")
        points[:, 2] = 0.0
        if kind == "quad4":
            clockwise = np.all(element_jacobians(points, cells, kind) < 0.0, axis=1)
            cells[clockwise] = cells[clockwise][:, [0, 3, 2, 1]]

    groups = _groups(raw, label)
    if abaqus is not None and len(abaqus["elset_of_block"]) == len(raw.cells):
        # meshio files *ELEMENT, ELSET=name under the wrong block when some
        # *ELEMENT blocks have no ELSET; rebuild those sets from the blocks
        params = abaqus["elset_of_block"]
        for name in set(filter(None, params)) - abaqus["elsets"]:
            groups[name] = [np.arange(len(b)) if p == name else np.zeros(0, np.int64)
                            for p, b in zip(params, raw.cells)]
    # element indices: block b's local element i is old element offset[b] + i
    offset = dict(zip(keep, np.cumsum([0] + [len(raw.cells[b]) for b in keep])))
    element_sets, node_sets = {}, {}
    for name, local in groups.items():
        try:
            members = [elem_map[offset[b] + local[b]] for b in keep if local[b].size]
            nodes = [np.asarray(raw.cells[b].data, dtype=np.int64)[a].reshape(-1)
                     for b, a in enumerate(local) if a.size]
        except IndexError:
            raise ValueError(f"{label}: group {name!r} refers to elements that do not "
                             "exist; check the file's sets") from None
        if members:
            element_sets[name] = np.concatenate(members)
        nodes = node_map[np.concatenate(nodes)] if nodes else np.zeros(0, np.int64)
        if np.any(nodes >= 0):
            node_sets[name] = nodes[nodes >= 0]
    for name, idx in (raw.point_sets or {}).items():
        nodes = node_map[np.asarray(idx, dtype=np.int64).reshape(-1)]
        if np.any(nodes >= 0):
            node_sets[name] = nodes[nodes >= 0]
        else:
            node_sets.pop(name, None)
    element_sets.setdefault("all", np.arange(cells.shape[0]))
    node_sets.setdefault("all", np.arange(points.shape[0]))
    return MeshData(points, cells, kind, node_sets=node_sets, element_sets=element_sets,
                    element_ids=element_ids, node_ids=node_ids, source=f"file '{path}'")
