"""Figures of a mass field: the histogram of the paper's Fig. 5.

(The mass map of Fig. 6 is the output field ``mass``:
``sphdyn plot DIR --snapshots mass``.) Drawn with Matplotlib's
object-oriented API on the Agg canvas and saved atomically.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..io.plots import per_depth, save_figure

__all__ = ["plot_mass_histogram"]


def plot_mass_histogram(masses, path, bins: int = 40, law=None, scale: float = 1.0,
                        m0: float | None = None, title: str = "",
                        dimension: int | None = None) -> Path:
    """Histogram of particle masses (paper Fig. 5), in grams.

    Parameters
    ----------
    masses : (N,) particle masses [kg] (kg/m in 2D).
    path : output PNG.
    law : optional law of the mass factors (``mass.distribution(spec)``); its
        density, mapped to masses by ``m = m0 * scale * f``, is drawn over the
        histogram (needs ``m0``).
    dimension : 2 or 3, the run's dimension: masses in g/m (2D, per unit
        depth) or g (3D); unknown: both named.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    g = np.asarray(masses, float) * 1e3
    fig = Figure(figsize=(5.0, 3.4), dpi=130)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    ax.hist(g, bins=bins, density=True, color="0.6", edgecolor="0.3", lw=0.4,
            label=f"{g.size} particles")
    if law is not None and m0 is not None and not hasattr(law, "pmf"):
        # continuous law: its density mapped to masses (grams per unit factor)
        unit = m0 * scale * 1e3
        f = np.linspace(g.min(), g.max(), 400) / unit
        ax.plot(f * unit, np.gradient(law.cdf(f), f) / unit, "k-", lw=1.2,
                label="requested law")
    ax.set_xlabel(f"particle mass [{per_depth('g', dimension)}]")
    ax.set_ylabel("probability density [1/g]")
    if title:
        ax.set_title(title, fontsize=9)
    ax.legend(fontsize=8, frameon=False)
    fig.tight_layout()
    return save_figure(fig, path)
