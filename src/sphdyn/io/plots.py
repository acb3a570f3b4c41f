"""Figures of a run's history CSV: energy balance, contact forces, time step.

Figures are drawn with Matplotlib's object-oriented API on the non-interactive
Agg canvas (no pyplot, no display, global backend untouched) and saved
atomically.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .atomic import atomic_path
from .history import read_history_csv

__all__ = ["plot_history", "history_figures", "save_figure", "time_unit", "per_depth",
           "scaled_unit", "final_step_rows", "markdown_table",
           "run_dimension_and_end", "ENERGY_COLUMNS", "energy_columns", "relative_drift"]

#: Energy columns plotted first, in this order, when present. Any other
#: column starting with ``E_`` or ``W_`` is added after them.
ENERGY_COLUMNS = ("E_kinetic", "E_internal", "E_viscous", "E_contact",
                  "W_external", "E_total")


def _figure(nrows: int = 1, height: float = 4.0):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8.0, height * nrows), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, 1, sharex=True, squeeze=False)[:, 0]
    return fig, axes


def time_unit(duration: float) -> tuple[float, str]:
    """Factor and unit name for showing times of a run lasting ``duration`` [s].

    Nanoseconds below 1 us (time steps), microseconds below 1 ms,
    milliseconds below 1 s, seconds above: ``t * factor`` is the shown number.
    """
    duration = abs(float(duration))
    if 0.0 < duration < 1e-6:
        return 1e9, "ns"
    if duration < 1e-3:
        return 1e6, "µs"
    if duration < 1.0:
        return 1e3, "ms"
    return 1.0, "s"


def scaled_unit(magnitude: float, unit: str) -> tuple[float, str]:
    """Factor and prefixed unit for showing values up to ``magnitude`` [unit].

    The prefix (k, M, G) keeps the largest shown number below 1000:
    81,600 N is shown as 81.6 kN, 1.04e7 N as 10.4 MN; values below 1000
    (and zero, NaN) keep ``unit``. ``value * factor`` is the shown number.
    """
    magnitude = abs(float(magnitude))
    for factor, prefix in ((1e-9, "G"), (1e-6, "M"), (1e-3, "k")):
        if magnitude * factor >= 1.0:  # False for NaN
            return factor, prefix + unit
    return 1.0, unit


def per_depth(unit: str, dimension: int | None) -> str:
    """``unit`` as stored for a run of ``dimension``: per metre of depth in
    2D, per square metre of cross-section in 1D.

    2D runs are plane strain per unit depth, so an energy is in J/m and a
    force in N/m; 1D runs are uniaxial strain per unit cross-section (J/m²,
    N/m²); 3D runs keep ``unit``. Unknown dimension: all three spelled out.
    """
    if dimension == 3:
        return unit
    if dimension == 2:
        return f"{unit}/m"
    if dimension == 1:
        return f"{unit}/m²"
    return f"{unit} (3D), {unit}/m (2D) or {unit}/m² (1D)"


def run_dimension_and_end(outdir: str | os.PathLike) -> tuple[int | None, float | None]:
    """``run.dimension`` and ``run.t_end`` from ``outdir/deck.resolved.toml``.

    (None, None) when the file is missing or unreadable (e.g. a history CSV
    outside a run directory).
    """
    import tomllib

    try:
        with open(Path(outdir) / "deck.resolved.toml", "rb") as f:
            run = tomllib.load(f).get("run", {})
    except (OSError, tomllib.TOMLDecodeError):
        return None, None
    dim = run.get("dimension")
    t_end = run.get("t_end")
    return (int(dim) if dim in (1, 2, 3) else None,
            float(t_end) if isinstance(t_end, (int, float)) else None)


def save_figure(fig, path, dpi: float | None = None) -> Path:
    """Write ``fig`` as a PNG at ``path`` atomically, creating the folder, and
    release it (pyplot-managed figures are closed). Every figure of sphdyn is
    saved through here."""
    import sys

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=dpi)
    pyplot = sys.modules.get("matplotlib.pyplot")
    if pyplot is not None:  # no-op for figures pyplot does not manage
        pyplot.close(fig)
    return path


def energy_columns(columns: list[str]) -> list[str]:
    """The energy columns (``E_*``, ``W_*``) of a history, known ones first."""
    known = [c for c in ENERGY_COLUMNS if c in columns]
    other = [c for c in columns if c.startswith(("E_", "W_")) and c not in known]
    return known + other


def relative_drift(e_total: np.ndarray, energies: list[np.ndarray]) -> np.ndarray:
    """``(E_total - E_total[0]) / max|E|`` over all energy terms and times.

    Normalising by the largest energy magnitude (rather than by
    ``E_total[0]``, which is often zero) keeps the drift meaningful for runs
    that start at rest.
    """
    if e_total.size == 0:
        return e_total.copy()
    scale = max((np.nanmax(np.abs(e)) for e in energies if e.size), default=0.0)
    if not np.isfinite(scale) or scale == 0.0:
        scale = 1.0
    return (e_total - e_total[0]) / scale


def plot_history(csv_path: str | os.PathLike,
                 out_dir: str | os.PathLike | None = None,
                 force_window: float | None = None, dimension: int | None = None,
                 t_end: float | None = None) -> list[Path]:
    """Plot the history CSV of a run into ``energies.png``, ``forces.png``, ``dt.png``.

    The figures are those of :func:`history_figures`, written when their
    columns exist.

    Parameters
    ----------
    csv_path : str or os.PathLike
        History CSV written by :meth:`sphdyn.io.history.History.write_csv`.
    out_dir : str or os.PathLike, optional
        Directory of the figures; default the directory of ``csv_path``.
    force_window : float, optional
        Averaging window of the wall forces [s]; default the deck's default
        ``[output] force_window``.
    dimension, t_end : optional
        The run's dimension (1, 2 or 3: units per area, per depth or not) and
        end time [s]
        (marks a last step shortened to land on it); default read from
        ``deck.resolved.toml`` beside ``csv_path``.

    Returns
    -------
    list of pathlib.Path
        The figures written.
    """
    csv_path = Path(csv_path)
    out_dir = Path(out_dir) if out_dir is not None else csv_path.parent
    if dimension is None or t_end is None:
        dim_file, end_file = run_dimension_and_end(csv_path.parent)
        dimension = dim_file if dimension is None else dimension
        t_end = end_file if t_end is None else t_end
    figures = history_figures(read_history_csv(csv_path), csv_path.name, force_window,
                              dimension, t_end)
    return [save_figure(fig, out_dir / f"{name}.png", 120) for name, fig in figures.items()]


def markdown_table(rows: list[dict]) -> str:
    """A Markdown table of ``rows`` (dicts with the same keys, in order: the
    header), values as given (format them first)."""
    if not rows:
        return ""
    keys = list(rows[0])
    lines = ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    lines += ["| " + " | ".join(str(r[k]) for k in keys) + " |" for r in rows]
    return "\n".join(lines)


def _largest(data: dict[str, np.ndarray], columns: list[str]) -> float:
    """The largest finite magnitude in ``data``'s ``columns`` (0 if none)."""
    return max((float(np.max(np.abs(v), initial=0.0)) for c in columns
                if (v := data[c][np.isfinite(data[c])]).size), default=0.0)


def final_step_rows(time: np.ndarray, dt: np.ndarray, t_end: float | None) -> np.ndarray:
    """(n,) bool: the history rows that report the run's last step when it was
    shortened to land exactly on ``t_end`` [s].

    A row at time ``t`` reports the step ``dt`` taken from ``t`` (a row at
    ``t_end``, the run's last, the step that ended there), so the rows of
    the last step are the trailing rows with ``t + dt`` or ``t`` at
    ``t_end`` (to the run loop's 1e-12 of ``t_end``) whose step is shorter
    than the one reported by the row before them (else it was not
    shortened). None, or a history not ending at ``t_end`` (a run stopped
    early, a restart to a later end): no row.
    """
    rows = np.zeros(dt.size, bool)
    if t_end is None or dt.size < 2:
        return rows
    tol = 1e-12 * abs(t_end)
    if not abs(time[-1] - t_end) <= tol:  # stopped early, or another end time
        return rows
    lands = (np.abs(time + dt - t_end) <= tol) | (np.abs(time - t_end) <= tol)
    first = dt.size
    while first > 0 and lands[first - 1]:  # the trailing rows of the last step
        first -= 1
    if first > 0:
        rows[first:] = dt[first:] < dt[first - 1]
    return rows


#: curves above which a legend goes beside the axes in columns of this many
LEGEND_ROWS = 12


def _finish_axes(ax, title: str) -> None:
    """Title, legend and grid; a long legend (many bars' forces) in columns
    beside the axes, small, so that it does not squeeze the plot away."""
    ax.set_title(title)
    n = len(ax.get_legend_handles_labels()[0])
    if n > LEGEND_ROWS:
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="x-small",
                  ncol=-(-n // LEGEND_ROWS))
    else:
        ax.legend(loc="best")
    ax.grid(True, alpha=0.3)


def history_figures(data: dict[str, np.ndarray], title: str = "",
                    force_window: float | None = None, dimension: int | None = None,
                    t_end: float | None = None) -> dict:
    """The history figures of a run, unsaved, by name (``energies``, ``forces``,
    ``reactions``, ``dt``).

    * ``energies``: every ``E_*``/``W_*`` column against time, and the
      relative drift of ``E_total`` in a second panel;
    * ``forces``: every ``F_*`` column against time, and for each wall with
      an impulse column ``I_wall_<name>`` its force averaged over
      ``force_window`` (:func:`sphdyn.analysis.fragments.window_mean_force`, dashed);
    * ``reactions``: the reaction force components ``<set>_reaction_x|y|z``
      of prescribed motions (components that stay zero left out);
    * ``dt``: ``dt`` against ``step`` (or time if there is no step), from 0.
      The last step, shortened to land exactly on ``t_end``
      (:func:`final_step_rows`), is left out (a note says so), so it does not
      look like a collapse of the time step.

    Times are shown in µs, ms or s from the run's duration (:func:`time_unit`);
    energies and forces in J and N in 3D, J/m and N/m in 2D, J/m² and N/m²
    in 1D (``dimension``), with the prefix k, M or G where the values reach
    thousands (:func:`scaled_unit`).
    """
    columns = list(data)
    figures: dict = {}
    time = data.get("time")
    tf, tu = time_unit(np.max(np.abs(time)) if time is not None and time.size else 0.0)
    shown = time * tf if time is not None else None

    energy_cols = energy_columns(columns)
    if time is not None and energy_cols:
        has_total = "E_total" in data
        fig, axes = _figure(2 if has_total else 1)
        ef, eu = scaled_unit(_largest(data, energy_cols), "J")
        for c in energy_cols:
            axes[0].plot(shown, data[c] * ef, label=c)
        axes[0].set_ylabel(f"energy [{per_depth(eu, dimension)}]")
        _finish_axes(axes[0], f"Energy balance ({title})")
        if has_total:
            drift = relative_drift(data["E_total"], [data[c] for c in energy_cols])
            axes[1].plot(shown, drift, color="k", label="E_total drift")
            axes[1].set_ylabel("drift [-]")  # short: the formula is in the title
            _finish_axes(axes[1], "Relative energy drift (E_total - E_total(0)) / max|E|")
        axes[-1].set_xlabel(f"time [{tu}]")
        figures["energies"] = fig

    force_cols = [c for c in columns if c.startswith("F_")]
    if time is not None and force_cols:
        fig, (ax,) = _figure()
        ff, fu = scaled_unit(_largest(data, force_cols), "N")
        for c in force_cols:
            ax.plot(shown, data[c] * ff, label=c)
        if force_window is None:
            from ..deck.schema import Output

            force_window = Output.model_fields["force_window"].default
        for c in columns:
            if c.startswith("I_wall_") and f"F_wall_{c[7:]}" in data:
                from ..analysis.fragments import window_mean_force

                ax.plot(shown, ff * window_mean_force(time, data[c], force_window), "--",
                        label=f"F_wall_{c[7:]}, {force_window * 1e6:g} µs mean")
        ax.set_xlabel(f"time [{tu}]")
        ax.set_ylabel(f"force [{per_depth(fu, dimension)}]")
        _finish_axes(ax, f"Forces ({title})")
        figures["forces"] = fig

    reaction_cols = [c for c in columns if c.rsplit("_", 1)[0].endswith("_reaction")]
    largest = _largest(data, reaction_cols)
    reaction_cols = [c for c in reaction_cols  # round-off of a free component left out
                     if _largest(data, [c]) > 1e-9 * largest]
    if time is not None and reaction_cols:
        fig, (ax,) = _figure()
        rf, ru = scaled_unit(largest, "N")
        for c in reaction_cols:
            ax.plot(shown, data[c] * rf, label=c)
        ax.set_xlabel(f"time [{tu}]")
        ax.set_ylabel(f"reaction force [{per_depth(ru, dimension)}]")
        _finish_axes(ax, f"Reactions of prescribed node sets ({title})")
        figures["reactions"] = fig

    xkey = "step" if "step" in data else "time" if time is not None else None
    if "dt" in data and xkey is not None:
        fig, (ax,) = _figure()
        x = data["step"] if xkey == "step" else shown
        final = (final_step_rows(time, data["dt"], t_end) if time is not None
                 else np.zeros(data["dt"].size, bool))
        df, du = time_unit(np.max(np.abs(data["dt"][~final]), initial=0.0))
        dt = data["dt"] * df
        ax.plot(x[~final], dt[~final], label="dt")
        if final.any():
            ax.plot([], [], " ", label=f"(not drawn: the last step, {dt[final][-1]:.3g} "
                    f"{du}, shortened to end at t_end)")
        top = np.max(dt[~final], initial=0.0)
        ax.set_ylim(0.0, 1.15 * top if np.isfinite(top) and top > 0 else None)
        ax.set_xlabel("step [-]" if xkey == "step" else f"time [{tu}]")
        ax.set_ylabel(f"time step dt [{du}]")
        _finish_axes(ax, f"Time step ({title})")
        figures["dt"] = fig
    return figures


#: units of the gauges' columns (:mod:`sphdyn.watchers.gauges`)
GAUGE_UNITS = {"strain": "-", "displacement": "m", "velocity": "m/s", "force": "N"}


def plot_gauges(gauge_dir: str | os.PathLike, out_path: str | os.PathLike,
                dimension: int | None = None) -> Path | None:
    """One panel per gauge CSV of ``gauge_dir`` (``gauges/<name>.csv``), its
    columns against time, into ``out_path``; None without gauge files.
    Forces are per metre of depth in 2D (``dimension``)."""
    files = sorted(Path(gauge_dir).glob("*.csv"))
    if not files:
        return None
    data = [read_history_csv(f) for f in files]
    t_max = max((float(np.max(d["time"])) for d in data if d["time"].size), default=0.0)
    tf, tu = time_unit(t_max)
    fig, axes = _figure(len(files), 3.0)
    for ax, f, d in zip(axes, files, data):
        units = []
        for c in (c for c in d if c != "time"):
            ax.plot(d["time"] * tf, d[c], label=c)
            kind = c.rsplit("_", 1)[0]  # strain, displacement_z, force_x, ...
            unit = GAUGE_UNITS.get(kind, "")
            unit = per_depth(unit, dimension) if kind == "force" else unit
            units += [unit] if unit not in units else []
        ax.set_ylabel(", ".join(units))  # a point gauge may mix m and m/s
        _finish_axes(ax, f"gauge {f.stem}")
    axes[-1].set_xlabel(f"time [{tu}]")
    return save_figure(fig, out_path, 120)
