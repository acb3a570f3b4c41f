"""Mesh blocks in the output: .vtu of hexahedra, quads and lines, multi-block .pvd,
HDF5 frames with meshes, FrameWriter, export_vtk and readers (sphdyn.io)."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import h5py
import meshio
import numpy as np
import pytest

from sphdyn.io import (
    FrameWriter, MeshFrame, PvdDataSet, export_vtk, read_frame, read_frame_meshes,
    read_pvd, read_pvd_datasets, write_frame, write_mesh_vtu, write_pvd,
)

# --------------------------------------------------------------------- test data


def _hex_mesh(k: int = 0) -> MeshFrame:
    """Two hexahedra side by side along x (12 nodes), fields depending on ``k``.

    Node (i, j, l) of the 3 x 2 x 2 lattice has index i + 3 j + 6 l; each
    element lists its bottom face counter-clockwise, then its top face (VTK).
    """
    i, j, l = np.meshgrid(np.arange(3), np.arange(2), np.arange(2), indexing="ij")
    idx = (i + 3 * j + 6 * l).ravel()
    x = np.zeros((12, 3))
    x[idx] = np.column_stack([i.ravel(), j.ravel(), l.ravel()]) * 0.1
    x[:, 0] += 1e-3 * k
    node = lambda a, b, c: a + 3 * b + 6 * c  # noqa: E731
    cells = np.array([[node(e, 0, 0), node(e + 1, 0, 0), node(e + 1, 1, 0), node(e, 1, 0),
                       node(e, 0, 1), node(e + 1, 0, 1), node(e + 1, 1, 1), node(e, 1, 1)]
                      for e in range(2)])
    rng = np.random.default_rng(10 + k)
    return MeshFrame(
        points=x, cells=cells, kind="hex8",
        point_data={"displacement": x - x[0], "velocity": rng.normal(size=(12, 3)),
                    "fixed": np.arange(12) % 2 == 0},
        cell_data={"stress": rng.normal(size=(2, 3, 3)) * 1e6,  # not symmetric
                   "von_mises": rng.random(2), "damage": np.array([0.0, 0.5]),
                   "material": np.array([3, 4], dtype=np.int32)})


def _quad_mesh(k: int = 0) -> MeshFrame:
    """Three quads in a row, 2D node positions (padded with z = 0 in VTK)."""
    x = np.array([[a * 0.05, b * 0.05] for a in range(4) for b in range(2)])  # node 2a + b
    x[:, 1] += 1e-3 * k
    cells = np.array([[2 * a, 2 * a + 2, 2 * a + 3, 2 * a + 1] for a in range(3)])
    rng = np.random.default_rng(20 + k)
    return MeshFrame(points=x, cells=cells, kind="quad4",
                     point_data={"velocity": rng.normal(size=(8, 3))},
                     cell_data={"stress": rng.normal(size=(3, 3, 3)),
                                "plastic_strain": rng.random(3)})


def _particles(k: int = 0) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(k)
    return {"position": rng.normal(size=(5, 3)), "stress": rng.normal(size=(5, 9)),
            "damage": rng.random(5)}


def _meshes(k: int = 0) -> dict[str, MeshFrame]:
    return {"slab": _hex_mesh(k), "plate": _quad_mesh(k)}


def _assert_mesh_equal(a: MeshFrame, b: MeshFrame) -> None:
    assert a.kind == b.kind
    for got, ref in [(a.points, b.points), (a.cells, b.cells)]:
        assert got.dtype == ref.dtype
        np.testing.assert_array_equal(got, ref)
    for got, ref in [(a.point_data, b.point_data), (a.cell_data, b.cell_data)]:
        assert list(got) == list(ref)
        for name in ref:
            assert got[name].dtype == ref[name].dtype, name
            np.testing.assert_array_equal(got[name], ref[name], err_msg=name)


# ---------------------------------------------------------------- write_mesh_vtu


def test_hex_vtu_cells_connectivity_and_data(tmp_path):
    m = _hex_mesh()
    path = write_mesh_vtu(tmp_path / "hex.vtu", m.points, m.cells, m.kind,
                          m.point_data, m.cell_data)
    back = meshio.read(path)
    assert [c.type for c in back.cells] == ["hexahedron"]
    np.testing.assert_array_equal(back.cells[0].data, m.cells)
    np.testing.assert_array_equal(back.points, m.points)
    np.testing.assert_array_equal(back.point_data["displacement"], m.point_data["displacement"])
    np.testing.assert_array_equal(back.point_data["velocity"], m.point_data["velocity"])
    np.testing.assert_array_equal(back.point_data["fixed"], [1, 0] * 6)  # bool -> uint8
    assert back.point_data["fixed"].dtype == np.uint8
    np.testing.assert_array_equal(back.cell_data["von_mises"][0], m.cell_data["von_mises"])
    np.testing.assert_array_equal(back.cell_data["damage"][0], [0.0, 0.5])
    np.testing.assert_array_equal(back.cell_data["material"][0], [3, 4])
    assert back.cell_data["material"][0].dtype.kind == "i"
    # Tensors: 9 components, row-major (xx, xy, xz, yx, ...), as for particles.
    sig = m.cell_data["stress"]
    stress = back.cell_data["stress"][0]
    assert stress.shape == (2, 9)
    np.testing.assert_array_equal(stress, sig.reshape(2, 9))
    assert stress[1, 1] == sig[1, 0, 1] and stress[1, 3] == sig[1, 1, 0]
    assert ET.parse(path).getroot().get("type") == "UnstructuredGrid"


def test_quad_and_line_vtu(tmp_path):
    q = _quad_mesh()
    back = meshio.read(write_mesh_vtu(tmp_path / "q.vtu", q.points, q.cells, "quad4",
                                      cell_data=q.cell_data))
    assert [c.type for c in back.cells] == ["quad"]
    np.testing.assert_array_equal(back.cells[0].data, q.cells)
    np.testing.assert_array_equal(back.points[:, :2], q.points)
    np.testing.assert_array_equal(back.points[:, 2], 0.0)  # 2D padded
    np.testing.assert_array_equal(back.cell_data["stress"][0],
                                  q.cell_data["stress"].reshape(3, 9))
    x = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.5, 0.0]])
    conn = np.array([[0, 1], [1, 2]])
    back = meshio.read(write_mesh_vtu(tmp_path / "l.vtu", x, conn, "line2",
                                      point_data={"v": x[:, ::-1]},
                                      cell_data={"axial_force": np.array([1.5, -2.0])},
                                      compress=True))
    assert [c.type for c in back.cells] == ["line"]
    np.testing.assert_array_equal(back.cells[0].data, conn)
    np.testing.assert_array_equal(back.point_data["v"], x[:, ::-1])
    np.testing.assert_array_equal(back.cell_data["axial_force"][0], [1.5, -2.0])


def test_mesh_vtu_rejects_bad_input(tmp_path):
    m = _hex_mesh()
    path = tmp_path / "bad.vtu"
    with pytest.raises(ValueError, match="kind"):
        write_mesh_vtu(path, m.points, m.cells, "tet4")
    with pytest.raises(ValueError, match=r"\(E, 4\)"):
        write_mesh_vtu(path, m.points, m.cells, "quad4")
    with pytest.raises(ValueError, match="outside"):
        write_mesh_vtu(path, m.points[:8], m.cells, "hex8")
    with pytest.raises(ValueError, match="'damage'"):
        write_mesh_vtu(path, m.points, m.cells, "hex8", cell_data={"damage": np.zeros(12)})
    with pytest.raises(ValueError, match="'v'"):
        write_mesh_vtu(path, m.points, m.cells, "hex8", point_data={"v": np.zeros(2)})
    assert not path.exists() and list(tmp_path.iterdir()) == []  # nothing left behind


def test_mesh_frame_checks_its_arrays():
    m = _hex_mesh()
    assert (m.n_points, m.n_cells) == (12, 2)
    with pytest.raises(ValueError, match="kind"):
        MeshFrame(m.points, m.cells, "tet4")
    with pytest.raises(ValueError, match=r"\(E, 2\)"):
        MeshFrame(m.points, m.cells, "line2")
    with pytest.raises(ValueError, match="outside"):
        MeshFrame(m.points, m.cells - 1, "hex8")
    with pytest.raises(TypeError, match="integers"):
        MeshFrame(m.points, m.cells.astype(float), "hex8")
    with pytest.raises(ValueError, match="'stress'"):
        MeshFrame(m.points, m.cells, "hex8", cell_data={"stress": np.zeros((12, 3, 3))})
    with pytest.raises(ValueError, match="'u'"):
        MeshFrame(m.points, m.cells, "hex8", point_data={"u": np.zeros((2, 3))})


# ------------------------------------------------------------------------- .pvd


def test_pvd_lists_blocks_with_parts_and_names(tmp_path):
    entries = [PvdDataSet(t, f"vtk/{name}_{k}.vtu", part, name)
               for k, t in enumerate([0.0, 1e-4])
               for part, name in enumerate(["particles", "slab"])]
    path = write_pvd(tmp_path / "run.pvd", entries)
    ds = ET.parse(path).getroot().findall("./Collection/DataSet")
    assert [(d.get("timestep"), d.get("part"), d.get("name")) for d in ds] == [
        ("0.0", "0", "particles"), ("0.0", "1", "slab"),
        ("0.0001", "0", "particles"), ("0.0001", "1", "slab")]
    assert read_pvd_datasets(path) == entries
    assert read_pvd(path) == [(e.time, e.file) for e in entries]


def test_old_single_block_pvd_is_still_read(tmp_path):
    # A .pvd as written before mesh blocks existed (no name attribute).
    text = """<?xml version="1.0"?>
<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">
  <Collection>
    <DataSet timestep="0.0" group="" part="0" file="vtk/frame_00000.vtu" />
    <DataSet timestep="0.001" group="" part="0" file="vtk/frame_00001.vtu" />
  </Collection>
</VTKFile>
"""
    path = tmp_path / "particles.pvd"
    path.write_text(text)
    assert read_pvd(path) == [(0.0, "vtk/frame_00000.vtu"), (0.001, "vtk/frame_00001.vtu")]
    assert read_pvd_datasets(path) == [PvdDataSet(0.0, "vtk/frame_00000.vtu"),
                                       PvdDataSet(0.001, "vtk/frame_00001.vtu")]
    # (time, file) pairs are still written in exactly that form.
    write_pvd(tmp_path / "again.pvd", read_pvd(path))
    assert (tmp_path / "again.pvd").read_text() == text


# ------------------------------------------------------------------- HDF5 frames


def test_hdf5_frame_round_trip_with_meshes(tmp_path):
    path = write_frame(tmp_path / "f.h5", 2e-4, 7, _particles(), meshes=_meshes())
    meshes = read_frame_meshes(path)
    assert list(meshes) == ["slab", "plate"]
    for name, ref in _meshes().items():
        _assert_mesh_equal(meshes[name], ref)
    t, step, fields, _ = read_frame(path)  # the particles, without the meshes
    assert (t, step) == (2e-4, 7) and list(fields) == list(_particles())
    with h5py.File(path, "r") as f:
        g = f["meshes/slab"]
        assert g.attrs["kind"] == "hex8" and g["cells"].shape == (2, 8)
        assert g["cell_data/stress"].shape == (2, 3, 3)
    plain = write_frame(tmp_path / "p.h5", 0.0, 0, _particles())
    assert read_frame_meshes(plain) == {}
    with h5py.File(plain, "r") as f:
        assert "meshes" not in f


def test_hdf5_frame_rejects_bad_mesh_names(tmp_path):
    for bad in ("particles", "a/b", "", ".hidden"):
        with pytest.raises(ValueError, match="name"):
            write_frame(tmp_path / "f.h5", 0.0, 0, _particles(), meshes={bad: _hex_mesh()})
    with pytest.raises(ValueError, match="'meshes'"):
        write_frame(tmp_path / "f.h5", 0.0, 0, {**_particles(), "meshes": np.zeros(5)},
                    meshes={"slab": _hex_mesh()})
    with pytest.raises(TypeError, match="MeshFrame"):
        write_frame(tmp_path / "f.h5", 0.0, 0, _particles(), meshes={"slab": {}})
    assert not (tmp_path / "f.h5").exists()


# ------------------------------------------------------------------- FrameWriter


def _run(outdir, n: int = 3, vtk: bool = True) -> FrameWriter:
    fw = FrameWriter(outdir, vtk=vtk)
    for k in range(n):
        fw.write(k * 1e-4, 10 * k, _particles(k), meshes=_meshes(k))
    return fw


def test_frame_writer_writes_mesh_vtu_and_multiblock_pvd(tmp_path):
    _run(tmp_path)
    ds = read_pvd_datasets(tmp_path / "particles.pvd")
    assert [(d.time, d.part, d.name, d.file) for d in ds] == [
        (k * 1e-4, part, name, file)
        for k in range(3)
        for part, name, file in [(0, "particles", f"vtk/frame_0000{k}.vtu"),
                                 (1, "slab", f"vtk/slab/frame_0000{k}.vtu"),
                                 (2, "plate", f"vtk/plate/frame_0000{k}.vtu")]]
    # ParaView groups the entries of a time step by the timestep string.
    raw = ET.parse(tmp_path / "particles.pvd").getroot().findall("./Collection/DataSet")
    assert len({d.get("timestep") for d in raw}) == 3
    for k in range(3):
        hexes = meshio.read(tmp_path / "vtk" / "slab" / f"frame_0000{k}.vtu")
        ref = _hex_mesh(k)
        assert [c.type for c in hexes.cells] == ["hexahedron"]
        np.testing.assert_array_equal(hexes.points, ref.points)
        np.testing.assert_array_equal(hexes.cell_data["stress"][0],
                                      ref.cell_data["stress"].reshape(2, 9))
        quads = meshio.read(tmp_path / "vtk" / "plate" / f"frame_0000{k}.vtu")
        assert [c.type for c in quads.cells] == ["quad"]
        np.testing.assert_array_equal(quads.points[:, :2], _quad_mesh(k).points)
        parts = meshio.read(tmp_path / "vtk" / f"frame_0000{k}.vtu")
        np.testing.assert_array_equal(parts.points, _particles(k)["position"])
        _assert_mesh_equal(read_frame_meshes(tmp_path / "frames" / f"frame_0000{k}.h5")
                           ["slab"], ref)


def test_run_without_meshes_keeps_the_single_block_layout(tmp_path):
    fw = FrameWriter(tmp_path)
    fw.write(0.0, 0, _particles(), meshes={})
    fw.write(1e-4, 1, _particles(1))
    assert [p.name for p in (tmp_path / "vtk").iterdir()] != []
    assert all(p.is_file() for p in (tmp_path / "vtk").iterdir())  # no mesh folders
    raw = ET.parse(tmp_path / "particles.pvd").getroot().findall("./Collection/DataSet")
    assert all(d.get("name") is None and d.get("part") == "0" for d in raw)
    assert read_pvd(tmp_path / "particles.pvd") == [(0.0, "vtk/frame_00000.vtu"),
                                                   (1e-4, "vtk/frame_00001.vtu")]
    with h5py.File(tmp_path / "frames" / "frame_00000.h5", "r") as f:
        assert "meshes" not in f


def test_restart_drops_the_mesh_frames_after_the_restart_time(tmp_path):
    _run(tmp_path, n=4)
    fw = FrameWriter(tmp_path, start_after=1e-4)
    assert fw.next_index == 2
    for name in ("slab", "plate"):
        assert sorted(p.name for p in (tmp_path / "vtk" / name).iterdir()) == [
            "frame_00000.vtu", "frame_00001.vtu"]
    ds = read_pvd_datasets(tmp_path / "particles.pvd")
    assert [(d.time, d.name) for d in ds] == [
        (t, name) for t in (0.0, 1e-4) for name in ("particles", "slab", "plate")]
    fw.write(1.5e-4, 99, _particles(9), meshes=_meshes(9))
    ds = read_pvd_datasets(tmp_path / "particles.pvd")
    assert [(d.part, d.name, d.file) for d in ds[-3:]] == [
        (0, "particles", "vtk/frame_00002.vtu"), (1, "slab", "vtk/slab/frame_00002.vtu"),
        (2, "plate", "vtk/plate/frame_00002.vtu")]
    # A fresh run over the directory removes the mesh frames and their folders.
    FrameWriter(tmp_path)
    assert list((tmp_path / "vtk").iterdir()) == []
    assert read_pvd(tmp_path / "particles.pvd") == []


def test_export_vtk_reproduces_the_mesh_vtu(tmp_path):
    _run(tmp_path / "live")
    _run(tmp_path / "later", vtk=False)
    assert not (tmp_path / "later" / "vtk").exists()
    pvd = export_vtk(tmp_path / "later")
    assert pvd.read_text() == (tmp_path / "live" / "particles.pvd").read_text()
    files = sorted(p.relative_to(tmp_path / "live")
                   for p in (tmp_path / "live" / "vtk").rglob("*.vtu"))
    assert len(files) == 9  # 3 frames x (particles, slab, plate)
    for rel in files:
        assert (tmp_path / "later" / rel).read_bytes() == (tmp_path / "live" / rel).read_bytes()
