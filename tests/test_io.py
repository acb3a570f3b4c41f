"""Tests of sphdyn.io: atomic writes, HDF5 frames/checkpoints, VTK, histories, plots."""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from pathlib import Path

import meshio
import numpy as np
import pytest

from sphdyn.fields import FIELDS
from sphdyn.io import (
    FrameWriter, History, atomic_path, atomic_write_bytes,
    atomic_write_text, export_csv, export_vtk, particle_fields, plot_history,
    read_checkpoint, read_frame, read_history_csv, read_pvd, write_checkpoint,
    write_frame, write_pvd, write_vtu,
)
from sphdyn.state import Particles


def _leftovers(directory: Path) -> list[str]:
    """Temporary files left by atomic_path (hidden '.<name>.*.tmp')."""
    return [f.name for f in directory.iterdir() if f.name.endswith(".tmp")]


def _particles(n: int = 5, seed: int = 0) -> Particles:
    rng = np.random.default_rng(seed)
    p = Particles.allocate(n, dim=3, n_history=2)
    p.hist_names = ["eps_p", "kappa"]
    p.x0[:] = rng.normal(size=(n, 3))
    p.x[:] = p.x0 + 1e-3 * rng.normal(size=(n, 3))
    p.v[:] = rng.normal(size=(n, 3))
    p.m[:] = 1.0 + rng.random(n)
    p.rho[:] = 2400.0
    p.h[:] = 0.01
    p.e[:] = rng.random(n)
    p.damage[:] = rng.random(n)
    p.hist[:] = rng.random((n, 2))
    p.body[:] = np.arange(n) % 2
    p.mat[:] = 3
    p.bc[:] = np.arange(n) % 3
    s = rng.normal(size=(n, 3, 3)) * 1e6
    p.sig[:] = s + s.transpose(0, 2, 1)
    return p


def _frame_fields(n: int = 4, shift: float = 0.0) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(1)
    return {
        "position": rng.normal(size=(n, 3)) + shift,
        "velocity": rng.normal(size=(n, 3)),
        "stress": rng.normal(size=(n, 9)),
        "pressure": rng.normal(size=n),
        "body": np.arange(n, dtype=np.int32),
        "bc": np.zeros(n, dtype=np.int8),
    }


# ------------------------------------------------------------------------- atomic

class TestAtomic:
    def test_write_text_and_bytes(self, tmp_path):
        p = tmp_path / "sub" / "a.txt"
        atomic_write_text(p, "héllo\n")
        assert p.read_text(encoding="utf-8") == "héllo\n"
        atomic_write_bytes(p, b"\x00\x01")
        assert p.read_bytes() == b"\x00\x01"
        assert _leftovers(p.parent) == []

    def test_temp_is_in_same_directory(self, tmp_path):
        target = tmp_path / "x.bin"
        with atomic_path(target) as tmp:
            assert tmp.parent == tmp_path
            assert tmp != target
            tmp.write_bytes(b"data")
            assert not target.exists()  # invisible until the block succeeds
        assert target.read_bytes() == b"data"

    def test_failure_keeps_old_file_and_removes_temp(self, tmp_path):
        target = tmp_path / "result.txt"
        atomic_write_text(target, "old complete content\n")
        with pytest.raises(RuntimeError, match="crash"):
            with atomic_path(target) as tmp:
                with open(tmp, "w") as f:
                    f.write("half of the new con")
                    f.flush()
                    raise RuntimeError("crash mid-write")
        assert target.read_text() == "old complete content\n"
        assert _leftovers(tmp_path) == []
        assert sorted(f.name for f in tmp_path.iterdir()) == ["result.txt"]

    def test_failing_hdf5_writer_keeps_previous_frame(self, tmp_path):
        target = tmp_path / "frame.h5"
        write_frame(target, 1.0, 10, {"a": np.arange(3.0)})

        class Boom:
            def __array__(self, *args, **kwargs):
                raise RuntimeError("crash while writing a dataset")

        with pytest.raises(RuntimeError, match="crash"):
            write_frame(target, 2.0, 20, {"a": np.arange(5.0), "b": Boom()})
        t, step, fields, _ = read_frame(target)
        assert (t, step) == (1.0, 10)
        np.testing.assert_array_equal(fields["a"], np.arange(3.0))
        assert _leftovers(tmp_path) == []

    def test_failing_vtu_writer_keeps_previous_file(self, tmp_path, monkeypatch):
        target = tmp_path / "p.vtu"
        write_vtu(target, np.zeros((2, 3)), {"s": np.array([1.0, 2.0])})
        before = target.read_bytes()

        def broken_write(filename, *args, **kwargs):
            Path(filename).write_text("<VTKFile><Unstruc")  # partial output
            raise OSError("disk full")

        monkeypatch.setattr(meshio, "write", broken_write)
        with pytest.raises(OSError, match="disk full"):
            write_vtu(target, np.ones((3, 3)), {"s": np.zeros(3)})
        assert target.read_bytes() == before
        assert _leftovers(tmp_path) == []

    def test_permissions_are_not_private(self, tmp_path):
        target = tmp_path / "a.txt"
        atomic_write_text(target, "x")
        mask = os.umask(0)
        os.umask(mask)
        assert target.stat().st_mode & 0o777 == 0o666 & ~mask


# --------------------------------------------------------------------------- hdf5

class TestHdf5:
    def test_frame_round_trip(self, tmp_path):
        fields = _frame_fields()
        path = tmp_path / "f.h5"
        write_frame(path, 1.25e-4, 321, fields, {"deck": "beam.toml", "dim": 2})
        t, step, back, attrs = read_frame(path)
        assert t == 1.25e-4 and isinstance(t, float)
        assert step == 321 and isinstance(step, int)
        assert attrs == {"deck": "beam.toml", "dim": 2}
        assert list(back) == list(fields)  # order kept
        for k, v in fields.items():
            assert back[k].dtype == v.dtype
            np.testing.assert_array_equal(back[k], v)

    def test_frame_rejects_reserved_attrs(self, tmp_path):
        with pytest.raises(ValueError, match="reserved"):
            write_frame(tmp_path / "f.h5", 0.0, 0, {}, {"time": 3.0})

    def test_checkpoint_bitwise_round_trip(self, tmp_path):
        p = _particles(7)
        p.v[0, 0] = np.nan
        p.e[1] = -0.0
        p.e[2] = np.nextafter(1.0, 2.0)
        arrays = p.arrays()
        arrays["empty"] = np.zeros((0, 3))
        arrays["flags"] = np.array([True, False, True])
        scalars = {"time": 0.1 + 0.2, "step": 123456789012, "deck_hash": "abc",
                   "restarted": True, "dt": 1e-300}
        groups = {"contact": {"pairs": np.array([[1, 2], [3, 4]], dtype=np.int64),
                              "gap": np.array([1e-9, -2e-9])},
                  "empty_group": {}}
        path = tmp_path / "ck.h5"
        write_checkpoint(path, arrays, scalars, groups)
        a2, s2, g2 = read_checkpoint(path)

        assert list(a2) == list(arrays)
        for k, v in arrays.items():
            assert a2[k].dtype == v.dtype and a2[k].shape == v.shape, k
            assert a2[k].tobytes() == np.ascontiguousarray(v).tobytes(), k
        assert s2 == scalars
        assert {k: type(v) for k, v in s2.items()} == {k: type(v) for k, v in scalars.items()}
        assert s2["time"].hex() == (0.1 + 0.2).hex()
        assert set(g2) == {"contact", "empty_group"} and g2["empty_group"] == {}
        for k, v in groups["contact"].items():
            assert g2["contact"][k].tobytes() == v.tobytes()
        # The restored state rebuilds the particles exactly.
        q = Particles.from_arrays(3, {k: a2[k] for k in p.arrays()}, p.hist_names)
        assert q.sig.tobytes() == p.sig.tobytes()

    def test_checkpoint_rejects_bad_scalar(self, tmp_path):
        with pytest.raises(TypeError, match="scalar 'x'"):
            write_checkpoint(tmp_path / "ck.h5", {}, {"x": None})
        assert not (tmp_path / "ck.h5").exists()

    def test_read_checkpoint_rejects_frame(self, tmp_path):
        write_frame(tmp_path / "f.h5", 0.0, 0, {"a": np.zeros(1)})
        with pytest.raises(ValueError, match="not an sphdyn checkpoint"):
            read_checkpoint(tmp_path / "f.h5")


# ---------------------------------------------------------------------------- vtk

class TestVtk:
    def test_vtu_read_back_by_meshio(self, tmp_path):
        n = 6
        rng = np.random.default_rng(2)
        x = rng.normal(size=(n, 3))
        sig = rng.normal(size=(n, 3, 3))
        data = {"pressure": rng.normal(size=n), "velocity": rng.normal(size=(n, 3)),
                "stress": sig, "body": np.arange(n, dtype=np.int32),
                "active": np.arange(n) % 2 == 0}
        path = tmp_path / "p.vtu"
        write_vtu(path, x, data)

        mesh = meshio.read(path)
        np.testing.assert_array_equal(mesh.points, x)
        assert len(mesh.cells) == 1 and mesh.cells[0].type == "vertex"
        np.testing.assert_array_equal(mesh.cells[0].data.ravel(), np.arange(n))
        np.testing.assert_array_equal(mesh.point_data["pressure"], data["pressure"])
        np.testing.assert_array_equal(mesh.point_data["velocity"], data["velocity"])
        assert mesh.point_data["stress"].shape == (n, 9)
        np.testing.assert_array_equal(mesh.point_data["stress"].reshape(n, 3, 3), sig)
        assert mesh.point_data["body"].dtype.kind == "i"
        np.testing.assert_array_equal(mesh.point_data["body"], np.arange(n))
        np.testing.assert_array_equal(mesh.point_data["active"], [1, 0, 1, 0, 1, 0])

    def test_vtu_is_binary_with_tensor_components(self, tmp_path):
        path = tmp_path / "p.vtu"
        write_vtu(path, np.zeros((2, 3)), {"stress": np.zeros((2, 3, 3))})
        root = ET.parse(path).getroot()
        assert root.get("type") == "UnstructuredGrid"
        arrays = {da.get("Name"): da for da in root.iter("DataArray")}
        assert arrays["stress"].get("NumberOfComponents") == "9"
        assert arrays["stress"].get("format") == "binary"
        assert {"connectivity", "offsets", "types"} <= set(arrays)

    def test_vtu_compressed(self, tmp_path):
        x = np.zeros((100, 3))
        data = {"s": np.ones(100), "t": np.ones((100, 3, 3))}
        plain = write_vtu(tmp_path / "a.vtu", x, data)
        packed = write_vtu(tmp_path / "b.vtu", x, data, compress=True)
        assert ET.parse(packed).getroot().get("compressor") == "vtkZLibDataCompressor"
        assert packed.stat().st_size < plain.stat().st_size
        np.testing.assert_array_equal(meshio.read(packed).point_data["t"], np.ones((100, 9)))

    def test_vtu_2d_positions_padded_and_shape_checked(self, tmp_path):
        path = tmp_path / "p.vtu"
        write_vtu(path, np.ones((3, 2)), {})
        np.testing.assert_array_equal(meshio.read(path).points[:, 2], 0.0)
        with pytest.raises(ValueError, match="'s'"):
            write_vtu(path, np.ones((3, 3)), {"s": np.zeros(4)})

    def test_pvd_valid_xml(self, tmp_path):
        entries = [(0.0, "vtk/frame_00000.vtu"), (1e-5, "vtk/frame_00001.vtu"),
                   (0.1 + 0.2, str(tmp_path / "vtk" / "frame_00002.vtu"))]
        path = write_pvd(tmp_path / "run.pvd", entries)
        root = ET.parse(path).getroot()
        assert root.tag == "VTKFile" and root.get("type") == "Collection"
        ds = root.findall("./Collection/DataSet")
        assert [d.get("file") for d in ds] == [
            "vtk/frame_00000.vtu", "vtk/frame_00001.vtu", "vtk/frame_00002.vtu"]
        assert [float(d.get("timestep")) for d in ds] == [0.0, 1e-5, 0.1 + 0.2]
        assert read_pvd(path) == [(t, f"vtk/frame_0000{i}.vtu")
                                  for i, (t, _) in enumerate(entries)]


# ------------------------------------------------------------------------- fields

class TestFields:
    def _with_stress(self, sig: np.ndarray) -> Particles:
        p = Particles.allocate(1, dim=3)
        p.sig[0] = sig
        return p

    def test_uniaxial_stress(self):
        for s in (5.0e6, -3.0e6):  # tension and compression
            p = self._with_stress(np.diag([s, 0.0, 0.0]))
            f = particle_fields(p, ["pressure", "von_mises"])
            assert f["pressure"][0] == pytest.approx(-s / 3.0)
            assert f["von_mises"][0] == pytest.approx(abs(s))

    def test_pure_shear(self):
        tau = 2.0e6
        sig = np.zeros((3, 3))
        sig[0, 1] = sig[1, 0] = tau
        f = particle_fields(self._with_stress(sig), ["von_mises", "pressure"])
        assert f["von_mises"][0] == pytest.approx(math.sqrt(3.0) * tau)
        assert f["pressure"][0] == pytest.approx(0.0, abs=1e-9)

    def test_hydrostatic_has_no_von_mises(self):
        f = particle_fields(self._with_stress(-7e6 * np.eye(3)), ["pressure", "von_mises"])
        assert f["pressure"][0] == pytest.approx(7e6)
        assert f["von_mises"][0] == pytest.approx(0.0, abs=1e-6)

    def test_all_fields(self):
        p = _particles(5)
        names = [n for n, f in FIELDS.items() if f.shape != "history"] + p.hist_names
        f = particle_fields(p, names)
        always = ["position", "mass"]  # first, then the others in the order asked
        cells = {n for n, f in FIELDS.items() if f.getter is None}  # meshes' only
        assert cells and list(f) == always + [n for n in names
                                              if n not in always and n not in cells]
        np.testing.assert_array_equal(f["position"], p.x)
        np.testing.assert_array_equal(f["velocity"], p.v)
        np.testing.assert_array_equal(f["displacement"], p.x - p.x0)
        np.testing.assert_array_equal(f["stress"].reshape(5, 3, 3), p.sig)
        np.testing.assert_array_equal(f["density"], p.rho)
        np.testing.assert_array_equal(f["mass"], p.m)
        np.testing.assert_array_equal(f["smoothing_length"], p.h)
        np.testing.assert_array_equal(f["damage"], p.damage)
        np.testing.assert_array_equal(f["internal_energy"], p.e)
        np.testing.assert_array_equal(f["material"], p.mat)
        np.testing.assert_array_equal(f["body"], p.body)
        assert f["bc"].dtype == np.int8
        np.testing.assert_array_equal(f["kappa"], p.hist[:, 1])
        np.testing.assert_array_equal(f["eps_p"], p.hist[:, 0])

    def test_position_always_and_copies(self):
        p = _particles(3)
        f = particle_fields(p, ["velocity"])
        assert list(f) == ["position", "mass", "velocity"]
        f["position"][:] = 0.0
        f["velocity"][:] = 0.0
        f["mass"][:] = 0.0
        assert np.all(p.x != 0.0) and np.all(p.v != 0.0) and np.all(p.m != 0.0)

    def test_unknown_name(self):
        p = _particles(2)
        with pytest.raises(ValueError, match="temperature.*allowed.*von_mises.*eps_p"):
            particle_fields(p, ["velocity", "temperature"])


# ------------------------------------------------------------------------ history

class TestHistory:
    def _history(self) -> History:
        h = History()
        for k in range(5):
            t = k * 0.1  # 0.30000000000000004 etc. must survive
            h.append({"time": t, "step": k, "E_kinetic": 1.0 / 3.0 + k, "F_wall": -k * 1e-7})
        return h

    def test_columns_and_key_check(self):
        h = self._history()
        assert h.columns == ["time", "step", "E_kinetic", "F_wall"]
        h.append({"F_wall": 0.0, "E_kinetic": 0.0, "step": 5, "time": 0.5})  # any order
        assert len(h) == 6 and h.as_arrays()["step"][-1] == 5.0
        with pytest.raises(ValueError, match="missing.*F_wall"):
            h.append({"time": 1.0, "step": 6, "E_kinetic": 0.0})
        with pytest.raises(ValueError, match="unexpected.*E_new"):
            h.append({"time": 1.0, "step": 6, "E_kinetic": 0.0, "F_wall": 0.0, "E_new": 1.0})
        assert len(h) == 6

    def test_csv_round_trip_exact(self, tmp_path):
        h = self._history()
        path = h.write_csv(tmp_path / "history.csv")
        assert path.read_text().splitlines()[0] == "time,step,E_kinetic,F_wall"
        back = read_history_csv(path)
        ref = h.as_arrays()
        assert list(back) == list(ref)
        for k in ref:
            assert back[k].tobytes() == ref[k].tobytes(), k
        assert back["time"][3] == 3 * 0.1

    def test_truncate_and_continue(self, tmp_path):
        path = self._history().write_csv(tmp_path / "history.csv")
        h = History.from_csv(path)
        assert h.columns == ["time", "step", "E_kinetic", "F_wall"]
        assert h.truncate_after(0.2) == 2
        np.testing.assert_array_equal(h.as_arrays()["step"], [0, 1, 2])
        h.append({"time": 0.25, "step": 3, "E_kinetic": 9.0, "F_wall": 0.0})
        h.write_csv(path)
        back = read_history_csv(path)
        np.testing.assert_array_equal(back["time"], [0.0, 0.1, 0.2, 0.25])
        with pytest.raises(ValueError):
            h.append({"time": 0.3})

    def test_empty(self):
        h = History()
        assert h.columns == [] and h.as_arrays() == {} and h.truncate_after(1.0) == 0


# -------------------------------------------------------------------------- plots

def test_energy_drift_is_relative_to_the_largest_energy_term():
    # A quasi-static test: the kinetic energy stays ~1e-3 J while internal
    # and contact energy grow to +-100 J and cancel; E_total drifts by 1 J.
    # Relative to the largest term that is exactly 1 % (a scale taken from
    # E_kinetic alone would give 1000); the columns are found by prefix.
    from sphdyn.io.plots import energy_columns, relative_drift

    t = np.linspace(0.0, 1.0, 11)
    h = {"time": t, "E_kinetic": np.full(11, 1e-3), "E_internal": 100.0 * t,
         "E_contact": -99.0 * t, "W_external": 0.0 * t, "F_wall_base": 5e5 * t}
    h["E_total"] = h["E_kinetic"] + h["E_internal"] + h["E_contact"]
    cols = energy_columns(list(h))
    assert cols == ["E_kinetic", "E_internal", "E_contact", "W_external", "E_total"]
    drift = relative_drift(h["E_total"], [h[c] for c in cols])
    assert drift[0] == 0.0
    assert np.max(np.abs(drift)) == pytest.approx(0.01, rel=1e-12)
    assert relative_drift(np.zeros(3), [np.zeros(3)]).tolist() == [0.0, 0.0, 0.0]


def test_plot_history_writes_pngs(tmp_path):
    h = History()
    for k in range(50):
        t = k * 1e-5
        ek = math.cos(1e4 * t) ** 2
        h.append({"time": t, "step": k, "dt": 1e-5 * (1 + 0.01 * k),
                  "E_kinetic": ek, "E_internal": 1.0 - ek, "W_external": 0.0,
                  "E_total": 1.0 + 1e-4 * k, "F_wall_floor": 10.0 * k, "F_contact": -k,
                  "I_wall_floor": 5.0 * k * k * 1e-5})
    csv_path = h.write_csv(tmp_path / "history.csv")
    out = tmp_path / "figs"
    paths = plot_history(csv_path, out)
    assert sorted(p.name for p in paths) == ["dt.png", "energies.png", "forces.png"]
    for p in paths:
        assert p.parent == out
        data = p.read_bytes()
        assert data.startswith(b"\x89PNG\r\n\x1a\n") and len(data) > 5000
    assert _leftovers(out) == []


def test_plot_history_only_existing_columns(tmp_path):
    h = History()
    for k in range(3):
        h.append({"time": float(k), "E_kinetic": 1.0})
    paths = plot_history(h.write_csv(tmp_path / "h.csv"))
    assert [p.name for p in paths] == ["energies.png"]
    assert paths[0].parent == tmp_path and paths[0].stat().st_size > 0


# ------------------------------------------------------------------------- frames

class TestFrameWriter:
    def test_writes_native_vtk_and_pvd(self, tmp_path):
        fw = FrameWriter(tmp_path)
        for k in range(3):
            assert fw.write(k * 1e-3, 10 * k, _frame_fields(shift=k)) == k
        names = [f.name for f in fw.frames_on_disk()]
        assert names == ["frame_00000.h5", "frame_00001.h5", "frame_00002.h5"]
        assert sorted(f.name for f in (tmp_path / "vtk").iterdir()) == [
            "frame_00000.vtu", "frame_00001.vtu", "frame_00002.vtu"]
        assert read_pvd(tmp_path / "particles.pvd") == [
            (k * 1e-3, f"vtk/frame_0000{k}.vtu") for k in range(3)]
        t, step, fields, _ = read_frame(tmp_path / "frames" / "frame_00002.h5")
        assert (t, step) == (2e-3, 20)
        np.testing.assert_array_equal(fields["position"], _frame_fields(shift=2)["position"])
        mesh = meshio.read(tmp_path / "vtk" / "frame_00001.vtu")
        np.testing.assert_array_equal(mesh.points, _frame_fields(shift=1)["position"])
        assert "position" not in mesh.point_data and "stress" in mesh.point_data
        with pytest.raises(ValueError, match="before"):
            fw.write(0.0, 0, _frame_fields())
        for d in (tmp_path, tmp_path / "frames", tmp_path / "vtk"):
            assert _leftovers(d) == []

    def test_fresh_run_over_existing_directory(self, tmp_path):
        fw = FrameWriter(tmp_path)
        assert fw.last_time is None
        for k in range(3):
            fw.write(float(k), k, _frame_fields())
        assert fw.last_time == 2.0 and fw.n_frames == 3
        with pytest.raises(FileExistsError):
            FrameWriter(tmp_path, overwrite=False)
        assert len(list((tmp_path / "frames").iterdir())) == 3  # nothing touched
        fw = FrameWriter(tmp_path)  # a new run replaces the old one
        assert fw.frames_on_disk() == [] and fw.last_time is None
        assert read_pvd(tmp_path / "particles.pvd") == []
        assert list((tmp_path / "vtk").iterdir()) == []
        assert fw.write(5.0, 0, _frame_fields()) == 0

    def test_restart_numbering(self, tmp_path):
        fw = FrameWriter(tmp_path)
        for k in range(5):
            fw.write(k * 0.1, k, _frame_fields(shift=k))
        # Restart from a checkpoint at t = 0.2: frames 3 and 4 are superseded.
        fw2 = FrameWriter(tmp_path, start_after=0.2)
        assert fw2.next_index == 3 and fw2.last_time == 0.2
        assert [f.name for f in fw2.frames_on_disk()] == [
            "frame_00000.h5", "frame_00001.h5", "frame_00002.h5"]
        assert [t for t, _ in read_pvd(tmp_path / "particles.pvd")] == [0.0, 0.1, 0.2]
        assert not (tmp_path / "vtk" / "frame_00004.vtu").exists()
        assert fw2.write(0.25, 3, _frame_fields(shift=9)) == 3
        entries = read_pvd(tmp_path / "particles.pvd")
        assert entries[-1] == (0.25, "vtk/frame_00003.vtu")
        assert len(entries) == 4
        t, _, fields, _ = read_frame(tmp_path / "frames" / "frame_00003.h5")
        assert t == 0.25
        np.testing.assert_array_equal(fields["position"], _frame_fields(shift=9)["position"])

    def test_export_vtk_and_csv(self, tmp_path):
        fw = FrameWriter(tmp_path, vtk=False)
        for k in range(2):
            fw.write(k * 0.5, k, _frame_fields(shift=k))
        assert not (tmp_path / "vtk").exists() and not (tmp_path / "particles.pvd").exists()
        pvd = export_vtk(tmp_path)
        assert pvd == tmp_path / "particles.pvd"
        assert read_pvd(pvd) == [(0.0, "vtk/frame_00000.vtu"), (0.5, "vtk/frame_00001.vtu")]
        for k in range(2):
            mesh = meshio.read(tmp_path / "vtk" / f"frame_0000{k}.vtu")
            ref = _frame_fields(shift=k)
            np.testing.assert_array_equal(mesh.points, ref["position"])
            np.testing.assert_array_equal(mesh.point_data["stress"], ref["stress"])

        csv_path = export_csv(tmp_path)
        assert csv_path == tmp_path / "frame_00001.csv"
        lines = csv_path.read_text().splitlines()
        header = lines[0].split(",")
        assert header[:4] == ["position_x", "position_y", "position_z", "velocity_x"]
        assert "stress_xy" in header and header[-2:] == ["body", "bc"]
        table = np.loadtxt(csv_path, delimiter=",", skiprows=1)
        ref = _frame_fields(shift=1)
        assert table.shape == (4, len(header))
        np.testing.assert_array_equal(table[:, :3], ref["position"])  # 17 digits: exact
        np.testing.assert_array_equal(table[:, header.index("stress_xy")], ref["stress"][:, 1])
        assert lines[1].split(",")[header.index("body")] == "0"
        first = export_csv(tmp_path, frame=0, path=tmp_path / "first.csv")
        first_table = np.loadtxt(first, delimiter=",", skiprows=1)
        np.testing.assert_array_equal(first_table[:, :3], _frame_fields(shift=0)["position"])
