"""Tests of sphdyn.geometry.mesh: generated meshes, Gmsh / Abaqus files, element checks.

Tolerances: generated coordinates come from ``numpy.linspace`` and are compared
exactly where a face coordinate is the box's (linspace's end points are exact);
volumes and areas, sums of products of coordinates, to 1e-12 relative. Files
are written with ``repr`` floats (exact round trip), so coordinates read back
are compared exactly.
"""

from __future__ import annotations

import numpy as np
import pytest

from sphdyn.geometry import (
    MeshData,
    block_mesh,
    check_elements,
    element_jacobians,
    line_mesh,
    polyline_mesh,
    read_mesh,
)

RTOL = 1e-12

# corner natural coordinates in VTK order, written out independently of the module
HEX_SIGNS = np.array([(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1),
                      (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)], dtype=float)
QUAD_SIGNS = HEX_SIGNS[:4, :2]


# --------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------
def hex_volumes(points, cells):
    """Element volumes by 2x2x2 Gauss integration of det J (exact for the
    trilinear hexahedron: det J is at most quadratic in each coordinate)."""
    g = 1.0 / np.sqrt(3.0)
    x = points[cells]                                   # (E, 8, 3)
    vol = np.zeros(len(cells))
    for xi in (-g, g):
        for eta in (-g, g):
            for zeta in (-g, g):
                s = HEX_SIGNS
                f = [1 + s[:, 0] * xi, 1 + s[:, 1] * eta, 1 + s[:, 2] * zeta]
                dn = np.stack([s[:, 0] * f[1] * f[2], s[:, 1] * f[0] * f[2],
                               s[:, 2] * f[0] * f[1]], axis=1) / 8.0     # (8, 3)
                jac = np.einsum("eai,aj->eij", x, dn)
                vol += np.linalg.det(jac)               # Gauss weights are 1
    return vol


def quad_areas(points, cells):
    """Signed polygon (shoelace) areas, exact for straight-edged quads."""
    x, y = points[cells][:, :, 0], points[cells][:, :, 1]
    return 0.5 * np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1)


def rows(a):
    """Point array as a sorted list of tuples (order-free comparison)."""
    return sorted(map(tuple, np.asarray(a).tolist()))


def element_shapes(mesh):
    """Elements as a set of frozensets of node coordinate tuples."""
    return {frozenset(map(tuple, mesh.points[c].tolist())) for c in mesh.cells}


def corner_signs(x):
    """(nen, d) sign pattern of an axis-aligned element's nodes about its centre."""
    return np.sign(x - x.mean(axis=0))


# --------------------------------------------------------------------------
# generated meshes
# --------------------------------------------------------------------------
@pytest.mark.parametrize("div", [(1, 1, 1), (3, 2, 4)])
def test_block_mesh_3d(div):
    lo, hi = np.array([-0.1, 0.0, 0.2]), np.array([0.2, 0.05, 0.5])
    m = block_mesh(lo, hi, div, 3)
    nx, ny, nz = div
    assert m.kind == "hex8" and m.points.dtype == np.float64 and m.cells.dtype == np.int64
    assert m.points.shape == ((nx + 1) * (ny + 1) * (nz + 1), 3)
    assert m.cells.shape == (nx * ny * nz, 8)
    assert np.array_equal(m.node_ids, np.arange(1, m.n_nodes + 1))
    assert np.array_equal(m.element_ids, np.arange(1, m.n_elements + 1))
    assert np.all(element_jacobians(m.points, m.cells, "hex8") > 0.0)
    for c in m.cells:  # VTK node order, not just a positive orientation
        assert np.array_equal(corner_signs(m.points[c]), HEX_SIGNS)
    box = np.prod(hi - lo)
    vol = hex_volumes(m.points, m.cells)
    assert abs(vol.sum() - box) <= RTOL * box
    np.testing.assert_allclose(vol, box / m.n_elements, rtol=RTOL)
    assert np.array_equal(m.element_set("all"), np.arange(m.n_elements))
    assert np.array_equal(m.node_set("all"), np.arange(m.n_nodes))
    for a, axis in enumerate("xyz"):
        for side, value in (("min", lo[a]), ("max", hi[a])):
            s = m.node_set(axis + side)
            assert s.size == np.prod([n + 1 for n in div]) // (div[a] + 1)
            assert np.array_equal(s, np.flatnonzero(m.points[:, a] == value))  # exact


def test_block_mesh_2d():
    m = block_mesh([0.0, -0.02, 7.0], [0.3, 0.04, 9.0], (3, 2), 2)  # z ignored
    assert m.kind == "quad4" and m.cells.shape == (6, 4) and m.points.shape == (12, 3)
    assert np.all(m.points[:, 2] == 0.0)
    assert np.all(element_jacobians(m.points, m.cells, "quad4") > 0.0)
    for c in m.cells:
        assert np.array_equal(corner_signs(m.points[c][:, :2]), QUAD_SIGNS)
    area = quad_areas(m.points, m.cells)
    assert abs(area.sum() - 0.3 * 0.06) <= RTOL * 0.018
    assert set(m.node_sets) == {"all", "xmin", "xmax", "ymin", "ymax"}
    assert np.array_equal(m.node_set("xmax"), np.flatnonzero(m.points[:, 0] == 0.3))
    assert m.node_set("xmax").size == 3 and m.node_set("ymin").size == 4
    assert np.array_equal(m.node_set("ymin"), np.flatnonzero(m.points[:, 1] == -0.02))


@pytest.mark.parametrize("smallest", ["lo", "hi", "centre"])
@pytest.mark.parametrize("n", [1, 2, 5, 8])
def test_graded_axis_grows_geometrically_from_its_smallest_element(n, smallest):
    """graded_nodes: the ends exactly lo and hi, the sizes summing to the
    length (1e-12), the largest `ratio` times the smallest (1e-12) and each
    neighbour's size ratio the same constant q = ratio^(1/k_max) away from
    the smallest element(s); ratio 1 gives numpy.linspace's bits."""
    from sphdyn.geometry.mesh_blocks import graded_nodes

    x = graded_nodes(-0.36, 0.12, n, 4.0, smallest)
    assert x[0] == -0.36 and x[-1] == 0.12 and x.size == n + 1
    s = np.diff(x)
    assert np.all(s > 0.0)
    assert abs(s.sum() - 0.48) <= RTOL * 0.48
    k = {"lo": np.arange(n), "hi": np.arange(n)[::-1],
         "centre": np.abs(np.arange(n) - (n - 1) / 2)}[smallest]
    k = k - k.min()
    if k.max() == 0:  # one element, or two about the centre: equal
        assert np.array_equal(x, np.linspace(-0.36, 0.12, n + 1))
        return
    assert s.max() / s.min() == pytest.approx(4.0, rel=RTOL)
    q = 4.0 ** (1.0 / k.max())
    np.testing.assert_allclose(s / s.min(), q ** k, rtol=1e-12)
    assert np.array_equal(graded_nodes(-0.36, 0.12, n), np.linspace(-0.36, 0.12, n + 1))


def test_a_graded_block_keeps_the_box_its_faces_and_positive_elements():
    """A 3D block graded on two axes: the same node sets and element count as
    the equal one, the volume the box's (1e-12), every Jacobian positive, the
    smallest elements where asked (about the middle in x, at z = hi)."""
    g = [(3.0, "centre"), (1.0, "lo"), (2.0, "hi")]
    m = block_mesh([-0.15, 0.0, -0.36], [0.15, 0.1, 0.0], (7, 2, 6), 3, g)
    e = block_mesh([-0.15, 0.0, -0.36], [0.15, 0.1, 0.0], (7, 2, 6), 3)
    assert m.cells.shape == e.cells.shape and np.array_equal(m.cells, e.cells)
    assert set(m.node_sets) == set(e.node_sets)
    for name in m.node_sets:
        assert np.array_equal(m.node_set(name), e.node_set(name))
    assert np.all(element_jacobians(m.points, m.cells, "hex8") > 0.0)
    vol = hex_volumes(m.points, m.cells)
    assert abs(vol.sum() - 0.3 * 0.1 * 0.36) <= RTOL * 0.0108
    xs, zs = np.unique(m.points[:, 0]), np.unique(m.points[:, 2])
    assert np.argmin(np.diff(xs)) == 3 and np.argmin(np.diff(zs)) == 5
    with pytest.raises(ValueError, match="grading"):
        block_mesh([0, 0, 0], [1, 1, 1], (2, 2, 2), 3, [(0.5, "lo")] * 3)


def test_line_mesh():
    m = line_mesh([0.0, 0.0, 0.0], [0.3, 0.4, 0.0], 5)
    assert m.kind == "line2" and m.cells.shape == (5, 2) and m.points.shape == (6, 3)
    length = element_jacobians(m.points, m.cells, "line2")
    np.testing.assert_allclose(length, 0.1, rtol=RTOL)
    assert np.array_equal(m.points[-1], [0.3, 0.4, 0.0])
    assert m.node_set("start").tolist() == [0] and m.node_set("end").tolist() == [5]
    assert line_mesh([0, 0], [1, 0], 1).points.shape == (2, 3)


def test_polyline_mesh_closed_stirrups_repeated():
    """A closed rectangle 0.1 x 0.2 m in the y-z plane, 2 + 4 + 2 + 4
    elements, three copies 0.25 m apart along x: corners exactly as given
    and shared by their two segments, every element 0.05 m (the perimeter /
    12), each copy one loop (every node in exactly two elements), the copies
    shifted by k step and unconnected; start = end = each copy's first node."""
    corners = [[0, 0, 0], [0, 0.1, 0], [0, 0.1, 0.2], [0, 0, 0.2]]
    m = polyline_mesh(corners, [2, 4, 2, 4], closed=True, copies=3, step=[0.25, 0, 0])
    assert m.kind == "line2" and m.cells.shape == (36, 2) and m.points.shape == (36, 3)
    np.testing.assert_allclose(element_jacobians(m.points, m.cells, "line2"), 0.05,
                               rtol=RTOL)
    assert np.array_equal(m.points[[0, 2, 6, 8]], np.array(corners, float))
    assert np.array_equal(np.bincount(m.cells.ravel()), np.full(36, 2))
    assert np.array_equal(m.cells[11], [11, 0]) and np.array_equal(m.cells[12], [12, 13])
    for k in range(3):
        assert np.array_equal(m.points[12 * k:12 * (k + 1)], m.points[:12] + [0.25 * k, 0, 0])
    assert m.node_set("start").tolist() == [0, 12, 24] == m.node_set("end").tolist()
    open_ = polyline_mesh(corners[:3], [2, 4])  # an open bent bar: 7 nodes, ends apart
    assert open_.points.shape == (7, 3) and open_.node_set("end").tolist() == [6]
    assert np.array_equal(line_mesh([0, 0, 0], [1, 0, 0], 4).points,
                          polyline_mesh([[0, 0, 0], [1, 0, 0]], [4]).points)


def test_polyline_mesh_arguments_are_checked():
    with pytest.raises(ValueError, match="at least 3 points"):
        polyline_mesh([[0, 0, 0], [1, 0, 0]], [1, 1], closed=True)
    with pytest.raises(ValueError, match="one element count per segment"):
        polyline_mesh([[0, 0, 0], [1, 0, 0], [1, 1, 0]], [1])
    with pytest.raises(ValueError, match="differ"):
        polyline_mesh([[0, 0, 0], [1, 0, 0], [1, 0, 0]], [1, 1])
    with pytest.raises(ValueError, match="nonzero step"):
        polyline_mesh([[0, 0, 0], [1, 0, 0]], [1], copies=2)


def test_generator_arguments_are_checked():
    with pytest.raises(ValueError, match="divisions"):
        block_mesh([0, 0, 0], [1, 1, 1], (2, 2), 3)
    with pytest.raises(ValueError, match="divisions"):
        block_mesh([0, 0, 0], [1, 1, 1], (2, 0, 2), 3)
    with pytest.raises(ValueError, match="hi must be > lo"):
        block_mesh([0, 0, 0], [1, 0, 1], (1, 1, 1), 3)
    with pytest.raises(ValueError, match="differ"):
        line_mesh([1, 2, 3], [1, 2, 3], 4)


# --------------------------------------------------------------------------
# Gmsh files (written here as text)
# --------------------------------------------------------------------------
LO, HI = np.array([0.0, 0.0, 0.0]), np.array([0.2, 0.1, 0.3])
RNG_SEED = 20261124


def gmsh_model():
    """A 2x2x2 hex block as a Gmsh model: node tags shuffled and sparse, one
    unused node, hex node lists cyclically rotated (still VTK order), four
    bottom quads in surface group "bottom", all hexes in volume group
    "concrete" and the first hex also in volume group "core"."""
    ref = block_mesh(LO, HI, (2, 2, 2), 3)
    rng = np.random.default_rng(RNG_SEED)
    tags = 10 + 7 * rng.permutation(ref.n_nodes)          # node index -> file tag
    nodes = {int(tags[i]): ref.points[i] for i in rng.permutation(ref.n_nodes)}
    nodes[5] = np.array([1.0, 1.0, 1.0])                    # used by no element
    rot = [1, 2, 3, 0, 5, 6, 7, 4]
    hexes = [(500 + k, [int(tags[n]) for n in c[rot]]) for k, c in enumerate(ref.cells)]
    bottom = [c[:4] for c in ref.cells if np.all(ref.points[c[:4], 2] == 0.0)]
    quads = [(1 + k, [int(tags[n]) for n in c[::-1]]) for k, c in enumerate(bottom)]
    return ref, tags, nodes, quads, hexes


def num(v):
    return repr(float(v))


def write_msh22(path, nodes, quads, hexes, extra=()):
    out = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$PhysicalNames", "3",
           '2 1 "bottom"', '3 2 "concrete"', '3 3 "core"', "$EndPhysicalNames",
           "$Nodes", str(len(nodes))]
    out += [f"{t} {' '.join(num(v) for v in x)}" for t, x in nodes.items()]
    out += ["$EndNodes", "$Elements"]
    els = [f"{t} 3 2 1 1 {' '.join(map(str, n))}" for t, n in quads]
    els += [f"{t} 5 2 2 1 {' '.join(map(str, n))}" for t, n in hexes]
    # MSH 2.2 repeats an element once per further physical group
    els += [f"{900} 5 2 3 1 {' '.join(map(str, hexes[0][1]))}"]
    els += list(extra)
    out += [str(len(els))] + els + ["$EndElements", ""]
    path.write_text("\n".join(out))
    return path


def write_msh41(path, nodes, quads, hexes):
    out = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat", "$PhysicalNames", "3",
           '2 1 "bottom"', '3 2 "concrete"', '3 3 "core"', "$EndPhysicalNames",
           "$Entities", "0 0 1 2",
           # surfaceTag box numPhysicalTags tags numBoundingCurves
           "1 0 0 0 0.2 0.1 0 1 1 0",
           # volumeTag box numPhysicalTags tags numBoundingSurfaces tags
           "1 0 0 0 0.2 0.1 0.3 2 2 3 1 1",
           "2 0 0 0 0.2 0.1 0.3 1 2 0",
           "$EndEntities", "$Nodes"]
    tags = list(nodes)
    out += [f"1 {len(tags)} {min(tags)} {max(tags)}", f"3 1 0 {len(tags)}"]
    out += [str(t) for t in tags] + [" ".join(num(v) for v in nodes[t]) for t in tags]
    out += ["$EndNodes", "$Elements"]
    alltags = [t for t, _ in quads + hexes]
    out += [f"3 {len(alltags)} {min(alltags)} {max(alltags)}"]
    out += [f"2 1 3 {len(quads)}"] + [f"{t} {' '.join(map(str, n))}" for t, n in quads]
    # hex 0 in volume 1 (groups concrete + core), the others in volume 2 (concrete)
    out += ["3 1 5 1", f"{hexes[0][0]} {' '.join(map(str, hexes[0][1]))}"]
    out += [f"3 2 5 {len(hexes) - 1}"]
    out += [f"{t} {' '.join(map(str, n))}" for t, n in hexes[1:]]
    out += ["$EndElements", ""]
    path.write_text("\n".join(out))
    return path


@pytest.mark.parametrize("version", ["2.2", "4.1"])
def test_gmsh_hex_block_reads_as_block_mesh(tmp_path, version):
    ref, tags, nodes, quads, hexes = gmsh_model()
    writer = write_msh22 if version == "2.2" else write_msh41
    m = read_mesh(writer(tmp_path / "block.msh", nodes, quads, hexes), 3)
    assert m.kind == "hex8"
    # the unused node and the repeated element dropped
    assert m.n_nodes == ref.n_nodes and m.n_elements == ref.n_elements
    assert rows(m.points) == rows(ref.points)                            # exact
    assert element_shapes(m) == element_shapes(ref)
    assert np.all(element_jacobians(m.points, m.cells, "hex8") > 0.0)
    check_elements(m)
    # ids are the file's tags
    tag_of = {tuple(ref.points[i]): int(tags[i]) for i in range(ref.n_nodes)}
    assert [tag_of[tuple(p)] for p in m.points.tolist()] == m.node_ids.tolist()
    assert sorted(m.element_ids.tolist()) == [t for t, _ in hexes]
    # groups: volumes -> element sets + node sets, the surface -> a node set
    assert np.array_equal(m.element_set("concrete"), np.arange(8))
    core = m.element_set("core")
    assert core.size == 1 and m.element_ids[core[0]] == hexes[0][0]
    assert np.array_equal(m.node_set("bottom"), np.flatnonzero(m.points[:, 2] == 0.0))
    assert m.node_set("bottom").size == 9
    assert m.node_set("concrete").size == 27 and m.node_set("core").size == 8
    assert "bottom" not in m.element_sets
    with pytest.raises(ValueError, match="'concrete'.*'core'"):
        m.element_set("Concrete")


def test_gmsh_binary_file_numbers_by_position(tmp_path):
    """Binary MSH 2.2 (written by meshio): read, ids are 1-based positions."""
    import meshio

    ref = block_mesh(LO, HI, (2, 1, 1), 3)
    raw = meshio.Mesh(ref.points, [("hexahedron", ref.cells)],
                      cell_data={"gmsh:physical": [np.array([4, 5])],
                                 "gmsh:geometrical": [np.array([1, 1])]},
                      field_data={"left": np.array([4, 3]), "right": np.array([5, 3])})
    path = tmp_path / "binary.msh"
    meshio.gmsh.write(str(path), raw, fmt_version="2.2", binary=True)
    m = read_mesh(path, 3)
    assert np.array_equal(m.points, ref.points) and np.array_equal(m.cells, ref.cells)
    assert m.node_ids.tolist() == list(range(1, 13)) and m.element_ids.tolist() == [1, 2]
    assert m.element_set("left").tolist() == [0] and m.element_set("right").tolist() == [1]
    assert np.array_equal(m.node_set("right"), np.sort(ref.cells[1]))


def test_gmsh_2d_with_line_group_needs_kind(tmp_path):
    ref = block_mesh([0, 0, 0], [0.2, 0.1, 0], (2, 1), 2)
    nodes = {i + 1: p for i, p in enumerate(ref.points)}
    left = [i + 1 for i in ref.node_set("xmin")]
    text = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$PhysicalNames", "2",
            '1 1 "left"', '2 2 "plate"', "$EndPhysicalNames", "$Nodes", str(len(nodes))]
    text += [f"{t} {' '.join(num(v) for v in x)}" for t, x in nodes.items()]
    text += ["$EndNodes", "$Elements", "3", f"1 1 2 1 1 {left[0]} {left[1]}"]
    text += [f"{k + 2} 3 2 2 1 {' '.join(str(n + 1) for n in c)}" for k, c in enumerate(ref.cells)]
    text += ["$EndElements", ""]
    path = tmp_path / "plate.msh"
    path.write_text("\n".join(text))
    with pytest.raises(ValueError, match="kind=.*quad4"):
        read_mesh(path, 2)
    m = read_mesh(path, 2, kind="quad4")
    assert m.kind == "quad4" and element_shapes(m) == element_shapes(ref)
    assert rows(m.points[m.node_set("left")]) == rows(ref.points[ref.node_set("xmin")])
    assert m.element_ids.tolist() == [2, 3]
    beams = read_mesh(path, 2, kind="line2")
    assert beams.n_elements == 1 and beams.n_nodes == 2
    assert np.array_equal(beams.node_set("plate"), [0, 1])  # nodes of the other kind's group
    with pytest.raises(ValueError, match=r"no hexahedron \(hex8\) elements; the file holds "
                                         "1 line, 2 quad"):
        read_mesh(path, 3, kind="hex8")  # quads are no element kind in 3D


# --------------------------------------------------------------------------
# Abaqus files
# --------------------------------------------------------------------------
def test_abaqus_c3d8r(tmp_path):
    ref = block_mesh(LO, HI, (2, 2, 2), 3)
    nid = 1001 + np.arange(ref.n_nodes)
    lines = ["*HEADING", "test block", "** a comment", "*NODE"]
    lines += [f"{nid[i]}, {', '.join(num(v) for v in p)}" for i, p in enumerate(ref.points)]
    lines += ["*ELEMENT, TYPE=C3D8R, ELSET=CONCRETE"]
    lines += [f"{11 + k}, {', '.join(str(nid[n]) for n in c)}" for k, c in enumerate(ref.cells)]
    top = nid[ref.node_set("zmax")]
    lines += ["*NSET, NSET=TOP"] + [", ".join(map(str, top))]
    lines += ["*NSET, NSET=FIRST3, GENERATE", "1001, 1003, 1"]
    lines += ["*ELSET, ELSET=CORNER", "18", "*END STEP", ""]
    path = tmp_path / "block.inp"
    path.write_text("\n".join(lines))
    m = read_mesh(path, 3)
    assert m.kind == "hex8"
    assert np.array_equal(m.points, ref.points) and np.array_equal(m.cells, ref.cells)
    assert np.array_equal(m.node_ids, nid)
    assert np.array_equal(m.element_ids, 11 + np.arange(8))
    assert np.array_equal(m.element_set("CONCRETE"), np.arange(8))
    assert m.element_set("CORNER").tolist() == [7]
    assert np.array_equal(m.node_set("CORNER"), np.sort(ref.cells[7]))
    assert np.array_equal(m.node_set("TOP"), ref.node_set("zmax"))
    assert m.node_set("FIRST3").tolist() == [0, 1, 2]
    assert np.all(element_jacobians(m.points, m.cells, "hex8") > 0.0)


def test_abaqus_element_blocks_sets_and_trusses(tmp_path):
    """Two hex blocks (the second with ELSET=UPPER) and a truss block: the
    ELSET lands on the right elements, the truss needs kind= and its set
    becomes a node set of the hex mesh."""
    ref = block_mesh(LO, HI, (1, 1, 2), 3)
    lines = ["*NODE"] + [f"{i + 1}, {', '.join(num(v) for v in p)}"
                         for i, p in enumerate(ref.points)]
    hexes = [f"{k + 1}, {', '.join(str(n + 1) for n in c)}" for k, c in enumerate(ref.cells)]
    lines += ["*ELEMENT, TYPE=C3D8", hexes[0], "*ELEMENT, TYPE=C3D8R, ELSET=UPPER", hexes[1]]
    lines += ["*ELEMENT, TYPE=T3D2, ELSET=BAR", "50, 1, 2", ""]
    path = tmp_path / "two.inp"
    path.write_text("\n".join(lines))
    with pytest.raises(ValueError, match=r"several supported element kinds \(2 hex8, 1 line2\)"):
        read_mesh(path, 3)
    m = read_mesh(path, 3, kind="hex8")
    assert m.element_set("UPPER").tolist() == [1] and m.element_ids.tolist() == [1, 2]
    assert "BAR" not in m.element_sets and m.node_set("BAR").tolist() == [0, 1]
    bars = read_mesh(path, 3, kind="line2")
    assert bars.element_ids.tolist() == [50] and bars.element_set("BAR").tolist() == [0]
    path.write_text("\n".join(lines + ["*ELSET, ELSET=BOTH", "UPPER, BAR", ""]))
    with pytest.raises(ValueError, match=r"\*ELSET BOTH lists a set by name \(UPPER\)"):
        read_mesh(path, 3, kind="hex8")


def test_abaqus_cpe4r_plane_strain(tmp_path):
    """2D: nodes given as x, y only; the mesh numbered clockwise (as a surface
    with normal -z) comes back counter-clockwise."""
    ref = block_mesh([0, 0], [0.2, 0.1], (2, 1), 2)
    lines = ["*NODE"] + [f"{i + 1}, {num(p[0])}, {num(p[1])}" for i, p in enumerate(ref.points)]
    lines += ["*ELEMENT, TYPE=CPE4R, ELSET=PLATE"]
    lines += [f"{k + 1}, {', '.join(str(n + 1) for n in c[::-1])}" for k, c in enumerate(ref.cells)]
    lines += ["*NSET, NSET=LEFT", ", ".join(str(i + 1) for i in ref.node_set("xmin")), ""]
    path = tmp_path / "plate.inp"
    path.write_text("\n".join(lines))
    m = read_mesh(path, 2)
    assert m.kind == "quad4" and np.array_equal(m.points, ref.points)
    assert element_shapes(m) == element_shapes(ref)
    assert np.all(element_jacobians(m.points, m.cells, "quad4") > 0.0)
    np.testing.assert_allclose(quad_areas(m.points, m.cells), 0.01, rtol=RTOL)
    assert np.array_equal(m.node_set("LEFT"), ref.node_set("xmin"))
    assert np.array_equal(m.element_set("PLATE"), [0, 1])


def _abaqus_quads(path, z):
    lines = ["*NODE", f"1, 0., 0., {z[0]}", f"2, 1., 0., {z[1]}", f"3, 1., 1., {z[2]}",
             f"4, 0., 1., {z[3]}", "*ELEMENT, TYPE=CPE4", "7, 1, 2, 3, 4", ""]
    path.write_text("\n".join(lines))
    return path


def test_2d_mesh_must_be_planar(tmp_path):
    m = read_mesh(_abaqus_quads(tmp_path / "flat.inp", [0.5] * 4), 2)
    assert np.all(m.points[:, 2] == 0.0) and m.element_ids.tolist() == [7]
    with pytest.raises(ValueError, match=r"node 3 has z = 0\.01.*plane"):
        read_mesh(_abaqus_quads(tmp_path / "bent.inp", [0, 0, 0.01, 0]), 2)


# --------------------------------------------------------------------------
# element checks
# --------------------------------------------------------------------------
def _block(n=3):
    m = block_mesh([0, 0, 0], [1, 1, 1], (n, n, n), 3)
    m.element_ids = 100 + 3 * np.arange(m.n_elements)  # ids as a file would have them
    return m


def test_check_elements_names_an_inverted_element():
    m = _block()
    m.cells[13] = m.cells[13][[4, 5, 6, 7, 0, 1, 2, 3]]  # top and bottom swapped: mirrored
    assert np.all(element_jacobians(m.points, m.cells, "hex8")[13] < 0.0)
    with pytest.raises(ValueError, match=r"1 inverted element.*ids 139;.*node order") as err:
        check_elements(m)
    assert "degenerate" not in str(err.value)


def test_check_elements_names_a_degenerate_element():
    m = _block()
    m.cells[5, 6] = m.cells[5, 7]  # two corners collapsed onto one node
    with pytest.raises(ValueError, match=r"1 degenerate element.*ids 115;.*duplicate") as err:
        check_elements(m)
    assert "inverted" not in str(err.value)
    flat = block_mesh([0, 0], [1, 1], (2, 2), 2)
    flat.points[flat.cells[3]] = flat.points[flat.cells[3][0]]  # zero area (and neighbours bent)
    with pytest.raises(ValueError, match=r"degenerate element.*ids .*\b4\b"):
        check_elements(flat)
    beam = line_mesh([0, 0, 0], [1, 0, 0], 3)
    beam.points[2] = beam.points[1]
    with pytest.raises(ValueError, match=r"1 degenerate element.*ids 2;"):
        check_elements(beam)


def test_check_elements_lists_at_most_ten_ids():
    m = _block()
    m.cells[:] = m.cells[:, [4, 5, 6, 7, 0, 1, 2, 3]]
    with pytest.raises(ValueError, match=r"27 inverted.*ids 100, 103, .*, 127 and 17 more"):
        check_elements(m)


def test_check_elements_passes_a_distorted_mesh():
    """Random node moves of up to 10 % of the spacing per axis (seeded); with
    the boundary nodes kept on their faces the volumes still sum to the box."""
    n, h = 4, 0.25
    m = block_mesh([0, 0, 0], [1, 1, 1], (n, n, n), 3)
    rng = np.random.default_rng(7)
    move = rng.uniform(-0.1 * h, 0.1 * h, m.points.shape)
    on_face = np.isin(np.arange(m.n_nodes), np.concatenate(
        [m.node_set(f) for f in ("xmin", "xmax", "ymin", "ymax", "zmin", "zmax")]))
    inner = m.points.copy()
    inner[~on_face] += move[~on_face]
    check_elements(MeshData(inner, m.cells, "hex8"))
    vol = hex_volumes(inner, m.cells)
    assert abs(vol.sum() - 1.0) <= RTOL and np.ptp(vol) > 0.01 * h**3
    every = m.points + move                               # boundary nodes moved as well
    check_elements(MeshData(every, m.cells, "hex8"))


# --------------------------------------------------------------------------
# error messages
# --------------------------------------------------------------------------
def test_missing_file(tmp_path):
    with pytest.raises(ValueError,
                       match=r"mesh file '.*nothere\.msh': no such file; check the path"):
        read_mesh(tmp_path / "nothere.msh", 3)


@pytest.mark.parametrize("name, content", [
    ("junk.msh", "this is not a mesh\n"),
    ("cut.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n1 0 0 0\n2 1 0"),
    ("junk.inp", "*NODE\n1, 0., 0., 0.\n*ELEMENT, TYPE=C3D8R\n1, 1, 2, 3\n"),
    ("undefined.inp", "*NODE\n1, 0., 0., 0.\n*ELEMENT, TYPE=C3D8R\n1, 1, 1, 1, 1, 1, 1, 1, 9\n"),
])
def test_unreadable_file(tmp_path, name, content):
    path = tmp_path / name
    path.write_text(content)
    with pytest.raises(ValueError, match=rf"mesh file '.*{name}': cannot read it as "
                                         r"(Gmsh|Abaqus) mesh.*check that it is a complete") as err:
        read_mesh(path, 3)
    if name == "undefined.inp":
        assert "id 9 is used but not defined" in str(err.value)


def test_several_node_blocks_are_refused(tmp_path):
    path = tmp_path / "nodes.inp"
    path.write_text("*NODE\n1, 0., 0., 0.\n*NODE\n2, 1., 0., 0.\n*ELEMENT, TYPE=T3D2\n1, 1, 2\n")
    with pytest.raises(ValueError, match=r"2 \*NODE blocks.*single \*NODE block"):
        read_mesh(path, 3)


def test_unsupported_extension_and_kind(tmp_path):
    path = tmp_path / "mesh.vtk"
    path.write_text("")
    with pytest.raises(ValueError, match=r"unsupported extension '\.vtk'.*\.msh.*\.inp"):
        read_mesh(path, 3)
    tets = tmp_path / "tets.inp"
    tets.write_text("*NODE\n1, 0., 0., 0.\n2, 1., 0., 0.\n3, 0., 1., 0.\n4, 0., 0., 1.\n"
                    "*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n")
    with pytest.raises(ValueError, match=r"no elements of a supported kind.*holds 1 tetra"):
        read_mesh(tets, 3)
    with pytest.raises(ValueError, match=r"kind must be one of \['hex8', 'line2'\]"):
        read_mesh(tets, 3, kind="quad4")


def test_unknown_set_name_lists_the_available():
    m = block_mesh([0, 0, 0], [1, 1, 1], (1, 1, 1), 3)
    with pytest.raises(ValueError, match=r"no node set named 'top'; available node sets: "
                                         r"'all', 'xmax', 'xmin', 'ymax', 'ymin', 'zmax', 'zmin'"):
        m.node_set("top")
    with pytest.raises(ValueError, match=r"no element set named 'x'.*'all'"):
        m.element_set("x")
