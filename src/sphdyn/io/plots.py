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

__all__ = ["plot_history", "save_figure", "ENERGY_COLUMNS", "energy_columns", "relative_drift"]

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
                 force_window: float | None = None) -> list[Path]:
    """Plot the history CSV of a run.

    Writes, when the needed columns exist:

    * ``energies.png``: every ``E_*``/``W_*`` column against ``time``, and the
      relative drift of ``E_total`` in a second panel;
    * ``forces.png``: every ``F_*`` column against ``time``, and for each
      wall with an impulse column ``I_wall_<name>`` its force averaged over
      ``force_window`` (:func:`sphdyn.analysis.window_mean_force`, dashed);
    * ``dt.png``: ``dt`` against ``step`` (or ``time`` if there is no step).

    Parameters
    ----------
    csv_path : str or os.PathLike
        History CSV written by :meth:`sphdyn.io.history.History.write_csv`.
    out_dir : str or os.PathLike, optional
        Directory of the figures; default the directory of ``csv_path``.
    force_window : float, optional
        Averaging window of the wall forces [s]; default the deck's default
        ``[output] force_window``.

    Returns
    -------
    list of pathlib.Path
        The figures written.
    """
    csv_path = Path(csv_path)
    out_dir = Path(out_dir) if out_dir is not None else csv_path.parent
    data = read_history_csv(csv_path)
    columns = list(data)
    written: list[Path] = []
    time = data.get("time")
    title = csv_path.name

    energy_cols = energy_columns(columns)
    if time is not None and energy_cols:
        has_total = "E_total" in data
        fig, axes = _figure(2 if has_total else 1)
        ax = axes[0]
        for c in energy_cols:
            ax.plot(time, data[c], label=c)
        ax.set_ylabel("energy [J] (J/m in 2D)")
        ax.set_title(f"Energy balance ({title})")
        ax.legend(loc="best")
        ax.grid(True, alpha=0.3)
        if has_total:
            drift = relative_drift(data["E_total"], [data[c] for c in energy_cols])
            axes[1].plot(time, drift, color="k", label="E_total drift")
            axes[1].set_ylabel("(E_total - E_total(0)) / max|E| [-]")
            axes[1].set_title("Relative energy drift")
            axes[1].legend(loc="best")
            axes[1].grid(True, alpha=0.3)
        axes[-1].set_xlabel("time [s]")
        written.append(save_figure(fig, out_dir / "energies.png", 120))

    force_cols = [c for c in columns if c.startswith("F_")]
    if time is not None and force_cols:
        fig, (ax,) = _figure()
        for c in force_cols:
            ax.plot(time, data[c], label=c)
        if force_window is None:
            from ..deck.schema import Output

            force_window = Output.model_fields["force_window"].default
        for c in columns:
            if c.startswith("I_wall_") and f"F_wall_{c[7:]}" in data:
                from ..analysis import window_mean_force

                ax.plot(time, window_mean_force(time, data[c], force_window), "--",
                        label=f"F_wall_{c[7:]}, {force_window * 1e6:g} us mean")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("force [N] (N/m in 2D)")
        ax.set_title(f"Forces ({title})")
        ax.legend(loc="best")
        ax.grid(True, alpha=0.3)
        written.append(save_figure(fig, out_dir / "forces.png", 120))

    xkey = "step" if "step" in data else "time" if time is not None else None
    if "dt" in data and xkey is not None:
        fig, (ax,) = _figure()
        ax.plot(data[xkey], data["dt"], label="dt")
        ax.set_xlabel("step [-]" if xkey == "step" else "time [s]")
        ax.set_ylabel("time step dt [s]")
        ax.set_title(f"Time step ({title})")
        ax.legend(loc="best")
        ax.grid(True, alpha=0.3)
        written.append(save_figure(fig, out_dir / "dt.png", 120))
    return written
