"""Snapshot panels (sphdyn.io.snapshots, .frame_data): frames, slabs, fields, PNGs, CLI."""

import matplotlib.image as mpimg
import numba
import numpy as np
import pytest

from sphdyn.cli import main
from sphdyn.deck import loads_deck
from sphdyn.io import list_frames, plot_snapshots, read_frame_header
from sphdyn.io.frame_data import (available_fields, field_values, particle_spacing,
                                  select_frames, slab_mask)
from sphdyn.simulation import Simulation

# A rubber disc (about 200 particles) hitting a wall: ~200 steps, 7 frames.
DISC_2D = """
[run]
title = "snapshot test disc"
dimension = 2
t_end = "0.6 ms"
[[material]]
name = "rubber"
model = "elastic"
density = 1000.0
E = 1e7
nu = 0.3
[[body]]
name = "disc"
material = "rubber"
dx = 1e-3
velocity = [0, -5.0]
geometry = { shape = "cylinder", centre = [0, 0.0086], radius = 0.008 }
[[wall]]
name = "floor"
point = [0, 0]
normal = [0, 1]
[output]
every = "0.1 ms"
vtk = false
progress = false
"""

# A short 3D cylinder (about 500 particles, 6 layers along z) hitting a wall.
DISC_3D = """
[run]
title = "snapshot test cylinder"
dimension = 3
t_end = "0.15 ms"
[[material]]
name = "rubber"
model = "elastic"
density = 1000.0
E = 1e7
nu = 0.3
[[body]]
name = "disc"
material = "rubber"
dx = 1e-3
velocity = [0, -5.0, 0]
geometry = { shape = "cylinder", centre = [0, 0.0056, 0], radius = 0.005, length = 0.006, axis = "z" }
[[wall]]
name = "floor"
point = [0, 0, 0]
normal = [0, 1, 0]
[output]
every = "0.05 ms"
vtk = false
progress = false
"""


def _run(tmp_path_factory, text, name):
    numba.set_num_threads(1)
    out = tmp_path_factory.mktemp(name) / "run"
    summary = Simulation.from_deck(loads_deck(text), out).run()
    assert summary["status"] == "completed"
    return out


@pytest.fixture(scope="module")
def run2d(tmp_path_factory):
    return _run(tmp_path_factory, DISC_2D, "snap2d")


@pytest.fixture(scope="module")
def run3d(tmp_path_factory):
    return _run(tmp_path_factory, DISC_3D, "snap3d")


def _check_png(path, min_bytes=10_000):
    assert path.is_file()
    assert path.stat().st_size > min_bytes
    img = mpimg.imread(path)
    colours = np.unique(img[..., :3].reshape(-1, 3), axis=0)
    assert len(colours) > 2  # not blank
    return img


# ------------------------------------------------------------------ selection

class TestSelectFrames:
    times = np.array([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]) * 1e-4

    def test_n_evenly_spaced_with_first_and_last(self):
        assert select_frames(self.times, n=3) == [0, 3, 6]
        assert select_frames(self.times, n=4) == [0, 2, 4, 6]
        assert select_frames(self.times, n=2) == [0, 6]

    def test_n_one_is_last_and_n_large_is_all(self):
        assert select_frames(self.times, n=1) == [6]
        assert select_frames(self.times, n=50) == list(range(7))

    def test_times_pick_nearest(self):
        assert select_frames(self.times, times=[0.9e-4, 3.4e-4, 5.6e-4]) == [1, 3, 6]
        # Within half a frame interval of the ends: the first/last frame;
        # duplicates dropped; sorted.
        assert select_frames(self.times, times=[6.4e-4, -0.4e-4, 2.1e-4, 1.9e-4]) == [
            0, 2, 6]

    @pytest.mark.parametrize("t", [6.6e-4, -0.6e-4, 1.0])
    def test_times_outside_the_run_are_refused(self, t):
        """A time more than half a frame interval (0.05 ms here) past either
        end is refused naming the run's range (it once showed the last
        frame without a word)."""
        with pytest.raises(ValueError, match=r"outside the run.*span 0 to 0\.0006 s"):
            select_frames(self.times, times=[2e-4, t])

    def test_bad_input(self):
        with pytest.raises(ValueError):
            select_frames(self.times, n=0)
        with pytest.raises(ValueError):
            select_frames([], n=3)
        with pytest.raises(ValueError):
            select_frames(self.times, times=[])


class TestSlab:
    @staticmethod
    def lattice(nz, dx=1e-3):
        g = np.arange(5) * dx
        x, y, z = np.meshgrid(g, g, np.arange(nz) * dx, indexing="ij")
        return np.column_stack([x.ravel(), y.ravel(), z.ravel()])

    def test_odd_layers_only_mid_plane(self):
        x = self.lattice(5)  # z = 0..4 mm, mid-plane 2 mm
        keep = slab_mask(x, "z", 1.5e-3)
        assert keep.sum() == 25
        assert np.allclose(x[keep, 2], 2e-3)

    def test_even_layers_two_middle_planes(self):
        x = self.lattice(6)  # mid-plane 2.5 mm between layers 2 and 3
        keep = slab_mask(x, "z", 1.5e-3)
        assert set(np.round(x[keep, 2] * 1e3, 9)) == {2.0, 3.0}

    def test_axis_and_centre(self):
        x = self.lattice(5)
        keep = slab_mask(x, "x", 0.5e-3, centre=1e-3)
        assert np.allclose(x[keep, 0], 1e-3) and keep.sum() == 25
        assert np.array_equal(slab_mask(x, 1, 0.5e-3, centre=0.0), x[:, 1] == 0.0)
        with pytest.raises(ValueError):
            slab_mask(x, "w", 1e-3)
        with pytest.raises(ValueError):
            slab_mask(x, "z", 0.0)

    def test_spacing(self):
        x = self.lattice(3, dx=2.5e-3)
        assert particle_spacing(x) == pytest.approx(2.5e-3)
        flat = x[x[:, 2] == 0]
        assert particle_spacing(flat, dimension=2) == pytest.approx(2.5e-3)


# --------------------------------------------------------------------- fields

class TestFields:
    rng = np.random.default_rng(1)
    fields = {
        "position": rng.normal(size=(4, 3)),
        "velocity": np.array([[3.0, 4.0, 0.0]] * 4),
        "stress": np.arange(36, dtype=float).reshape(4, 9),
        "von_mises": np.ones(4),
    }

    def test_components_and_speed(self):
        syy, unit = field_values(self.fields, "stress_yy")
        assert np.array_equal(syy, self.fields["stress"][:, 4]) and unit == "Pa"
        sxy, _ = field_values(self.fields, "stress_xy")
        assert np.array_equal(sxy, self.fields["stress"][:, 1])
        speed, unit = field_values(self.fields, "speed")
        assert np.allclose(speed, 5.0) and unit == "m/s"
        vy, _ = field_values(self.fields, "velocity_y")
        assert np.allclose(vy, 4.0)
        assert np.allclose(field_values(self.fields, "velocity")[0], 5.0)

    def test_unknown_and_tensor(self):
        with pytest.raises(ValueError, match="available.*von_mises"):
            field_values(self.fields, "plastic_strain")
        with pytest.raises(ValueError, match="stress_xx"):
            field_values(self.fields, "stress")
        names = available_fields(self.fields)
        assert {"speed", "stress_zz", "von_mises", "velocity_x"} <= set(names)


# ---------------------------------------------------------------------- plots

def test_2d_panels(run2d):
    path = plot_snapshots(run2d, "von_mises", n=4)
    assert path == run2d / "plots" / "snapshots_von_mises.png"
    img = _check_png(path)
    # A colour-bar figure: some pixels are neither white nor grey.
    rgb = img[..., :3]
    assert np.any(rgb.max(axis=-1) - rgb.min(axis=-1) > 0.3)
    for field in ("damage", "pressure"):
        _check_png(plot_snapshots(run2d, field, n=2))


def test_times_and_out(run2d, tmp_path):
    out = tmp_path / "sub" / "fig.png"
    path = plot_snapshots(run2d, "stress_xx", times=[1.4e-4, 4.1e-4], out=out,
                          vmin=-1e5, vmax=1e5, cmap="coolwarm", marker_size=2e-3)
    assert path == out
    _check_png(out)
    assert not list(out.parent.glob(".*.tmp"))  # atomic write left nothing behind
    frame_times = [read_frame_header(f)[0] for f in list_frames(run2d)]
    idx = select_frames(frame_times, times=[1.4e-4, 4.1e-4])
    assert np.allclose([frame_times[i] for i in idx], [1e-4, 4e-4], rtol=0.05)


def test_bad_field(run2d):
    with pytest.raises(ValueError, match="available.*von_mises"):
        plot_snapshots(run2d, "no_such_field")
    assert not (run2d / "plots" / "snapshots_no_such_field.png").exists()


def test_bad_limits_and_empty_slab(run2d, run3d, tmp_path):
    with pytest.raises(ValueError, match="vmax"):
        plot_snapshots(run2d, "von_mises", vmin=1.0, vmax=0.0)
    # A slab between two lattice planes (x = ±0.5 mm) holds no particle:
    # empty panels rather than a failure.
    path = plot_snapshots(run3d, "von_mises", n=1, slice_axis="x",
                          slice_width=1e-4, out=tmp_path / "empty.png")
    assert path.is_file()


def test_cli_times_outside_the_run_exit_2_naming_the_range(run2d, capsys):
    """`sphdyn plot --times` beyond the run's frames exits 2 with the run's
    time range and writes nothing."""
    target = run2d / "plots" / "snapshots_density.png"
    assert main(["plot", str(run2d), "--snapshots", "density", "--times", "0.1 ms,5 ms"]) == 2
    err = capsys.readouterr().err
    assert "0.005 s is outside the run" in err and "0 to 0.0006 s" in err and "Fix:" in err
    assert not target.exists()


def test_no_frames(tmp_path):
    with pytest.raises(FileNotFoundError):
        plot_snapshots(tmp_path)


def test_3d_slab_panels(run3d):
    path = plot_snapshots(run3d, "von_mises", n=3)
    _check_png(path)
    side = plot_snapshots(run3d, "speed", n=2, slice_axis="y",
                          slice_width=3e-3, out=run3d / "side.png")
    _check_png(side)


def test_cli_snapshots(run2d, capsys):
    target = run2d / "plots" / "snapshots_von_mises.png"
    target.unlink(missing_ok=True)
    assert main(["plot", str(run2d), "--snapshots", "von_mises", "--n", "3"]) == 0
    _check_png(target)
    assert main(["plot", str(run2d), "--snapshots", "damage,speed",
                 "--snapshots", "stress_yy", "--times", "1e-4,0.3 ms"]) == 0
    printed = capsys.readouterr().out.split()
    assert [p.rsplit("/", 1)[-1] for p in printed] == [
        "snapshots_von_mises.png", "snapshots_damage.png", "snapshots_speed.png",
        "snapshots_stress_yy.png"]
    assert main(["plot", str(run2d), "--snapshots", "nope"]) == 2
    assert "available" in capsys.readouterr().err
    # Without --snapshots: the history plots, as before.
    assert main(["plot", str(run2d)]) == 0
    assert "energies.png" in capsys.readouterr().out


def test_several_runs_one_row_each(run2d, tmp_path):
    # Two runs (here the same one twice) -> a 2 x 3 grid, rows = runs; the
    # image is taller than the single-run figure with the same 3 panels,
    # whose grid packs them in one row.
    out2 = plot_snapshots([run2d, run2d], "von_mises", n=3, out=tmp_path / "two.png")
    out1 = plot_snapshots(run2d, "von_mises", n=3, out=tmp_path / "one.png")
    two, one = _check_png(out2), _check_png(out1)
    assert two.shape[0] > 1.5 * one.shape[0]
    assert main(["plot", str(run2d), str(run2d), "--snapshots", "speed", "--n", "2",
                 "--out", str(tmp_path / "cli.png")]) == 0
    _check_png(tmp_path / "cli.png")


def _run_1d(path, n_frames=3, with_deck=True):
    """A 1D run directory written directly: 41 particles on x in [-0.02, 0.02]
    m, frame k at t = k * 1e-5 s with density 1000 + k * x (kg/m^3)."""
    from sphdyn.io.hdf5 import write_frame

    x = np.linspace(-0.02, 0.02, 41)[::-1].copy()  # stored out of x order
    pos = np.column_stack([x, np.zeros_like(x), np.zeros_like(x)])
    for k in range(n_frames):
        write_frame(path / "frames" / f"frame_{k:05d}.h5", k * 1e-5, k,
                    {"position": pos, "density": 1000.0 + k * x,
                     "velocity": np.column_stack([k * x, 0 * x, 0 * x])})
    if with_deck:
        (path / "deck.resolved.toml").write_text('[run]\ntitle = "bar"\ndimension = 1\n')
    return path


@pytest.mark.parametrize("with_deck", [True, False])
def test_1d_snapshots_are_the_field_along_x_one_line_per_frame(tmp_path, monkeypatch,
                                                               with_deck):
    """A 1D run (the deck's dimension, or every y and z zero) gives one line
    per frame of the field against x, in x order, with the frame's time
    (it ended in an IndexError). Values are drawn as stored: exact."""
    from sphdyn.io import snapshots

    drawn = []
    real = snapshots.save_figure
    monkeypatch.setattr(snapshots, "save_figure",
                        lambda fig, dest, dpi=None: drawn.append(fig) or real(fig, dest, dpi))
    run = _run_1d(tmp_path / "r", with_deck=with_deck)
    path = plot_snapshots(run, "density", n=3)
    assert path == run / "plots" / "snapshots_density.png"
    _check_png(path, min_bytes=5_000)
    (ax,) = drawn[-1].axes
    lines = ax.get_lines()
    assert [ln.get_label() for ln in lines] == ["t = 0 µs", "t = 10 µs", "t = 20 µs"]
    x = np.linspace(-0.02, 0.02, 41)
    for k, ln in enumerate(lines):
        assert np.array_equal(ln.get_xdata(), x * 1e3)
        assert np.array_equal(ln.get_ydata(), 1000.0 + k * x)
    assert ax.get_xlabel() == "x [mm]" and ax.get_ylabel() == "density [kg/m^3]"


def test_1d_snapshots_of_two_runs_and_through_the_cli(tmp_path, capsys):
    """Two 1D runs: one axes per run; the CLI writes the PNG and exits 0."""
    a = _run_1d(tmp_path / "a")
    b = _run_1d(tmp_path / "b", n_frames=2)
    assert main(["plot", str(a), str(b), "--snapshots", "velocity_x", "--out",
                 str(tmp_path / "two.png")]) == 0
    _check_png(tmp_path / "two.png", min_bytes=5_000)
    assert main(["plot", str(a), "--snapshots", "density,speed"]) == 0
    assert capsys.readouterr().out.split()[-1].endswith("snapshots_speed.png")
