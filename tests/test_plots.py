"""Figures say what they show: time units from the run's duration, energy and
force units from its dimension, the shortened last step marked, damage grids
with axes and a colour bar, phase slices with a legend, runs labelled by what
differs between them, material-point figures titled with their parameters.

Each test reads back the Matplotlib figure objects (or the saved PNG's size),
so it needs no run of the solver.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from sphdyn.ensemble.report import damage_grid_figure
from sphdyn.heterogeneity.mesostructure import (generate_phase_grid, phase_slice_figure,
                                                save_phase_slices)
from sphdyn.io.hdf5 import write_frame
from sphdyn.io.plots import (history_figures, per_depth, plot_history, scaled_unit,
                             time_unit)
from sphdyn.io.frame_data import run_labels
from sphdyn.materials.driver import drive, result_figure, result_title


def _history(t_end: float, n: int = 40, shortened: bool = True) -> dict:
    """A history of ``n`` rows to ``t_end``; the last step shortened to land on it."""
    time = np.linspace(0.0, t_end, n)
    dt = np.full(n, t_end / (n - 1))
    if shortened:
        dt[-1] *= 0.05
    return {"time": time, "step": np.arange(n, dtype=float), "dt": dt,
            "E_kinetic": np.cos(time / t_end) ** 2, "E_total": np.ones(n),
            "F_wall_floor": np.sin(time / t_end)}


@pytest.mark.parametrize("duration, factor, unit", [
    (2.5e-7, 1e9, "ns"), (4e-4, 1e6, "µs"), (12e-3, 1e3, "ms"), (2.0, 1.0, "s")])
def test_time_unit_follows_the_duration(duration, factor, unit):
    assert time_unit(duration) == (factor, unit)


@pytest.mark.parametrize("t_end, unit, factor", [(4e-4, "µs", 1e6), (12e-3, "ms", 1e3)])
def test_history_time_axes_are_scaled(t_end, unit, factor):
    data = _history(t_end)
    figs = history_figures(data, dimension=3, t_end=t_end)
    for name in ("energies", "forces"):
        ax = figs[name].axes[-1]
        assert ax.get_xlabel() == f"time [{unit}]"
        line = figs[name].axes[0].get_lines()[0]
        assert np.allclose(line.get_xdata(), data["time"] * factor)


@pytest.mark.parametrize("dimension, energy, force", [
    (3, "energy [J]", "force [N]"), (2, "energy [J/m]", "force [N/m]"),
    (1, "energy [J/m²]", "force [N/m²]")])
def test_energy_and_force_units_follow_the_dimension(dimension, energy, force):
    """3D in J and N; 2D plane strain per metre of depth; 1D uniaxial strain
    per square metre of cross-section (sod_shock_tube's axis said "J (3D) or
    J/m (2D)")."""
    figs = history_figures(_history(1e-3), dimension=dimension, t_end=1e-3)
    assert figs["energies"].axes[0].get_ylabel() == energy
    assert figs["forces"].axes[0].get_ylabel() == force
    unknown = per_depth("J", None)  # unknown: all three spelled out
    assert all(per_depth("J", d) in unknown for d in (1, 2, 3))


def test_plot_history_reads_the_dimension_from_the_run_directory(tmp_path, monkeypatch):
    from sphdyn.io import plots
    from sphdyn.io.history import History

    h = History()
    for k in range(5):
        h.append({"time": k * 1e-5, "step": k, "dt": 1e-5, "E_kinetic": 1.0})
    h.write_csv(tmp_path / "history.csv")
    seen = {}
    real = plots.history_figures

    def spy(data, title, force_window, dimension, t_end):
        seen.update(dimension=dimension, t_end=t_end)
        return real(data, title, force_window, dimension, t_end)

    monkeypatch.setattr(plots, "history_figures", spy)
    for dimension in (1, 3):  # a 1D run's dimension used to be read as unknown
        (tmp_path / "deck.resolved.toml").write_text(
            f"[run]\ndimension = {dimension}\nt_end = 4e-5\n")
        plot_history(tmp_path / "history.csv")
        assert seen == {"dimension": dimension, "t_end": 4e-5}


def test_the_shortened_last_step_is_not_part_of_the_dt_line():
    data = _history(1e-3)
    ax = history_figures(data, dimension=2, t_end=1e-3)["dt"].axes[0]
    main, note = ax.get_lines()
    # dt = 1e-3 / 39 = 25.6 us: shown in us
    assert ax.get_ylabel() == "time step dt [µs]"
    assert np.allclose(main.get_ydata(), data["dt"][:-1] * 1e6, rtol=1e-15)
    assert note.get_xdata().size == 0 and "shortened" in note.get_label()
    assert ax.get_ylim()[0] == 0.0  # from zero: a dip reads as the fraction it is
    # a run stopped before t_end (or without a known t_end) keeps every step
    assert len(history_figures(data, dimension=2, t_end=2e-3)["dt"].axes[0].get_lines()) == 1
    assert len(history_figures(data)["dt"].axes[0].get_lines()) == 1


def test_the_last_step_is_left_out_when_two_rows_report_it():
    """With history_every > 1 the row taken at the last kick and the final
    row at t_end both report the shortened step (beam_fem: 7.34 us after
    16.4 us); the old check (last dt below the one before) missed it and
    drew the drop as a collapse. final_step_rows finds both rows; a step
    that lands on t_end unshortened, a run stopped early and a history
    going past t_end have none."""
    from sphdyn.io.plots import final_step_rows

    time = np.array([0.0, 10.0, 20.0, 30.0, 32.0]) * 1e-6
    dt = np.array([1.0, 1.0, 1.0, 0.2, 0.2]) * 1e-6
    t_end = 30.2e-6
    time[-1] = t_end
    assert final_step_rows(time, dt, t_end).tolist() == [False, False, False, True, True]
    data = {"time": time, "step": np.arange(5.0), "dt": dt}
    ax = history_figures(data, dimension=3, t_end=t_end)["dt"].axes[0]
    assert np.array_equal(ax.get_lines()[0].get_ydata(), [1.0, 1.0, 1.0])  # in µs
    assert not final_step_rows(time, np.full(5, 1e-6), t_end).any()  # not shortened
    assert not final_step_rows(time, dt, 40e-6).any()  # stopped before t_end
    # restarted past the deck's t_end (sphdyn restart --t-end): nothing hidden
    assert not final_step_rows(np.append(time, 50e-6), np.append(dt, 1e-6), t_end).any()
    assert not final_step_rows(time, dt, None).any()


@pytest.mark.parametrize("magnitude, factor, unit", [
    (0.0, 1.0, "N"), (999.0, 1.0, "N"), (81600.0, 1e-3, "kN"), (1.04e7, 1e-6, "MN"),
    (-2.5e9, 1e-9, "GN"), (float("nan"), 1.0, "N")])
def test_scaled_unit_keeps_the_shown_numbers_below_a_thousand(magnitude, factor, unit):
    assert scaled_unit(magnitude, "N") == (factor, unit)


def test_forces_energies_and_reactions_are_shown_in_kn_kj_mn():
    """disc_impact's wall force peaks at 81.6 kN: shown in kN (the axis read
    80000 N), its window mean too; energies of 40 kJ in kJ, reactions of
    10 MN in MN (beam_fem's axis read 1e7 N)."""
    data = _history(1e-3)
    data["F_wall_floor"] = data["F_wall_floor"] * 81600.0
    data["I_wall_floor"] = np.cumsum(data["F_wall_floor"]) * 1e-3 / 39
    data["E_kinetic"] = data["E_kinetic"] * 4e4
    data["clamped_reaction_x"] = np.linspace(0.0, 1.04e7, data["time"].size)
    figs = history_figures(data, dimension=3, t_end=1e-3)
    ax = figs["forces"].axes[0]
    assert ax.get_ylabel() == "force [kN]"
    for line in ax.get_lines():
        assert np.max(np.abs(line.get_ydata())) < 1000.0, line.get_label()
    assert np.allclose(ax.get_lines()[0].get_ydata(), data["F_wall_floor"] * 1e-3,
                       rtol=1e-15)
    assert figs["energies"].axes[0].get_ylabel() == "energy [kJ]"
    assert figs["reactions"].axes[0].get_ylabel() == "reaction force [MN]"
    assert history_figures(data, dimension=2, t_end=1e-3)["forces"].axes[0].get_ylabel() \
        == "force [kN/m]"


def test_history_figures_keep_every_label_inside():
    """No label is cut off: the tight box of every drawn artist lies inside
    the figure (to 1 pixel), and each y label is shorter than its axes (the
    drift panel's label used to hold the whole formula)."""
    data = _history(1e-3)
    data["F_wall_floor"] = data["F_wall_floor"] * 81600.0
    for dimension in (1, 2, 3, None):
        for name, fig in history_figures(data, "history.csv", dimension=dimension,
                                         t_end=1e-3).items():
            fig.canvas.draw()
            r = fig.canvas.get_renderer()
            box, frame = fig.get_tightbbox(r), fig.bbox_inches
            assert box.x0 >= frame.x0 - 0.01 and box.y0 >= frame.y0 - 0.01, name
            assert box.x1 <= frame.x1 + 0.01 and box.y1 <= frame.y1 + 0.01, name
            for ax in fig.axes:
                height = ax.yaxis.label.get_window_extent(r).height
                assert height < ax.get_window_extent(r).height, (name, ax.get_ylabel())


def _run_dir(path, body_dx: float, title: str = "same title"):
    path.mkdir(parents=True)
    (path / "deck.resolved.toml").write_text(
        f'[run]\ntitle = "{title}"\ndimension = 2\nt_end = 0.001\n\n'
        f'[[body]]\nname = "disc"\ndx = {body_dx}\n')
    return path


def test_runs_side_by_side_are_labelled_by_directory_and_differing_values(tmp_path):
    a = _run_dir(tmp_path / "coarse", 0.002)
    b = _run_dir(tmp_path / "fine", 0.001)
    la, lb = run_labels([a, b])
    assert la.splitlines() == ["coarse", "body.disc.dx = 0.002"]
    assert lb.splitlines() == ["fine", "body.disc.dx = 0.001"]
    assert "same title" not in la + lb
    assert run_labels([a, tmp_path / "no_deck"])[1].splitlines()[0] == "no_deck"


def test_phase_slices_are_large_and_have_a_phase_legend(tmp_path):
    dx = 1e-3
    g = generate_phase_grid((24, 24, 24), dx, aggregate_fraction=0.4,
                            max_aggregate_size=8 * dx, itz_thickness=dx, seed=3)
    fig = phase_slice_figure(g, dx)
    legend = fig.legends[0]
    assert [t.get_text() for t in legend.get_texts()] == ["mortar", "aggregate", "ITZ"]
    assert [ax.get_xlabel() for ax in fig.axes] == ["x [mm]", "x [mm]", "y [mm]"]
    from PIL import Image

    png = save_phase_slices(g[:, :, 12], tmp_path / "p.png", dx)  # 2D: one panel
    assert min(Image.open(png).size) >= 500


def test_damage_grid_has_axes_and_a_colour_bar(tmp_path):
    x = np.stack(np.meshgrid(np.arange(10.0), np.arange(10.0)), -1).reshape(-1, 2) * 1e-3
    pos = np.column_stack([x, np.zeros(len(x))])
    recs = []
    for s, v in enumerate(["0.7", "1.5"]):
        d = tmp_path / f"sample_{s:04d}"
        write_frame(d / "frames" / "frame_00000.h5", 1e-4, 10,
                    {"position": pos, "damage": np.linspace(0, 1, len(x)),
                     "mass": np.ones(len(x))})
        recs.append({"sample": s, "seed": s, "vary": {"sph.support_scale": v},
                     "status": "completed", "main_cracks": 1, "dir": str(d)})
        (d / "result.json").write_text(json.dumps(recs[-1]))
    fig = damage_grid_figure(tmp_path)
    panels = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
    bars = [ax for ax in fig.axes if ax.get_label() == "<colorbar>"]
    assert len(panels) == 2 and len(bars) == 1
    assert bars[0].get_ylabel() == "damage [-]"
    assert panels[-1].get_xlabel() == "x [mm]"
    assert panels[0].get_ylabel().endswith("y [mm]")
    assert "sph.support_scale = 0.7" in panels[0].get_ylabel()
    assert len(panels[-1].get_xticks()) > 1
    assert "100 µs" in panels[0].get_title()


def test_material_point_figure_names_model_and_parameters():
    res = drive("elastic", {"density": 1000.0, "E": 1e7, "nu": 0.3},
                "uniaxial-tension", n_steps=20)
    title = result_title(res)
    assert title.startswith("elastic: uniaxial-tension")
    assert "E = 1e+07" in title and "nu = 0.3" in title and "G = " in title
    fig = result_figure(res)
    assert fig.axes[0].get_xlabel() == "strain eps_xx [‰]"
    assert np.allclose(fig.axes[0].get_lines()[0].get_xdata(), res["x"] * 1e3)
    assert fig.get_suptitle() == title


def test_markdown_table_from_rows():
    from sphdyn.io.plots import markdown_table
    text = markdown_table([{"a": 1, "b [mm]": "2.00"}, {"a": 3, "b [mm]": "4.00"}])
    assert text.splitlines() == ["| a | b [mm] |", "|---|---|", "| 1 | 2.00 |",
                                 "| 3 | 4.00 |"]
    assert markdown_table([]) == ""
