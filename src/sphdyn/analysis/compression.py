"""Uniaxial compression tests between rigid platens: stress-strain curves and statistics.

A specimen is loaded by a moving rigid wall (``[[wall]] velocity``) against
a fixed one. From a run's ``history.csv`` and its resolved deck:

.. math::
    \\varepsilon(t) = \\frac{d(t)}{H}, \\qquad
    \\sigma(t) = \\frac{F(t)}{A}, \\qquad A = \\frac{V}{H},

with :math:`d` the platen displacement along its normal (history column
``d_wall_<name>``), :math:`F` its normal contact force (``F_wall_<name>``,
N, or N/m in 2D), :math:`H` the specimen height along the platen normal
(extent of the particle lattice plus one spacing) and :math:`V` its volume
(particle count times :math:`\\Delta x^d`), so :math:`A` is the mean
cross-section of any prismatic specimen (in 2D the width, per unit depth).
Compression is reported positive (engineering stress and strain).

For an ensemble (``sphdyn ensemble``) :func:`ensemble_report` collects the
curves of every sample, their peak stress and strain at peak, the mean and
coefficient of variation, and draws all curves with the homogeneous model
highlighted (thesis Fig. 7.3).
"""

from __future__ import annotations

import csv
import json
import tomllib
from pathlib import Path

import numpy as np

from ..io.atomic import atomic_path
from ..io.plots import save_figure
from ..io import read_frame
from ..io.frames import frames_of_run
from ..io.history import read_history_csv

__all__ = ["compression_curve", "ensemble_report"]


class UnknownWall(ValueError):
    """The wall named is not a [[wall]] of the run: a mistake in the request,
    not in one sample, so :func:`ensemble_report` does not skip it."""


def _specimen(run_dir: Path, wall: str, moves: bool = True
              ) -> tuple[float, float, np.ndarray]:
    """Height H [m], cross-section A [m^2, m in 2D] and the wall normal (3,);
    ``moves``: whether the history has the wall's displacement."""
    with open(run_dir / "deck.resolved.toml", "rb") as f:
        deck = tomllib.load(f)
    walls = {w["name"]: w for w in deck.get("wall", [])}
    if wall not in walls:
        fix = (f"name the moving platen: one of {', '.join(walls)}" if walls else
               "give run directories of a deck whose platens are [[wall]]s")
        raise UnknownWall(f"{run_dir}: no [[wall]] named {wall!r} (walls: "
                          f"{', '.join(walls) or 'none'}). Fix: {fix}")
    if not moves:
        raise ValueError(f"{run_dir}: history has no 'd_wall_{wall}': wall {wall!r} does "
                         "not move. Fix: name the moving platen (a [[wall]] with a "
                         "velocity)")
    normal = np.asarray(walls[wall]["normal"], float)
    normal = np.pad(normal, (0, 3 - normal.size)) / np.linalg.norm(normal)
    dim = int(deck["run"]["dimension"])
    bodies = deck["body"]
    dx = float(bodies[0]["dx"])
    if any(float(b["dx"]) != dx for b in bodies):
        raise ValueError(f"{run_dir}: bodies with different dx; the specimen must be "
                         "one lattice")
    frames = frames_of_run(run_dir)
    x = np.asarray(read_frame(frames[0])[2]["position"], float)
    s = x @ normal
    height = float(s.max() - s.min()) + dx
    area = x.shape[0] * dx**dim / height
    return height, area, normal


def compression_curve(run_dir, wall: str) -> dict:
    """Engineering stress-strain curve of one run loaded by the moving wall ``wall``.

    Returns a dict with ``strain`` and ``stress`` [Pa] arrays (compression
    positive, one entry per history record), ``peak_stress`` [Pa],
    ``strain_at_peak``, ``height`` [m] and ``area`` [m^2] (m in 2D).
    """
    run_dir = Path(run_dir)
    h = read_history_csv(run_dir / "history.csv")
    key_f, key_d = f"F_wall_{wall}", f"d_wall_{wall}"
    height, area, _ = _specimen(run_dir, wall, moves=key_d in h)
    # d_wall is the displacement along the wall normal, i.e. into the specimen
    strain = h[key_d] / height
    stress = h[key_f] / area
    k = int(np.argmax(stress))
    return {"strain": strain, "stress": stress, "peak_stress": float(stress[k]),
            "strain_at_peak": float(strain[k]), "height": height, "area": area}


def _stats(values: np.ndarray) -> dict:
    mean = float(np.mean(values)) if values.size else float("nan")
    std = float(np.std(values, ddof=1)) if values.size > 1 else 0.0
    return {"mean": mean, "std": std, "cov": std / mean if mean else float("nan"),
            "n": int(values.size)}


def ensemble_report(sample_dirs, wall: str, out, homogeneous=None) -> dict:
    """Curves, peak statistics and the all-curves figure of an ensemble of runs.

    Parameters
    ----------
    sample_dirs : run directories (e.g. ``OUT/sample_*`` of ``sphdyn ensemble``);
        runs without history are skipped and counted.
    wall : name of the moving platen (a ValueError naming the run's walls if
        it has none of that name).
    out : directory for ``ucs_samples.csv`` (peak per sample),
        ``ucs_statistics.json`` (mean, std, coefficient of variation of peak
        stress and strain at peak) and ``ucs_curves.png``.
    homogeneous : optional run directory of the homogeneous model, drawn in
        black and reported separately.

    Returns
    -------
    dict with the statistics (as written to the JSON file).

    Raises
    ------
    ValueError
        If a run has no wall ``wall``, or no directory gives a curve.
    """
    out = Path(out)
    rows, curves, skipped, reasons = [], [], 0, []
    dirs = sorted(Path(s) for s in sample_dirs)
    for d in dirs:
        try:
            c = compression_curve(d, wall)
        except UnknownWall:
            raise
        except (FileNotFoundError, ValueError) as exc:
            skipped += 1
            reasons.append(str(exc))
            continue
        curves.append(c)
        rows.append({"sample": d.name, "peak_stress_Pa": c["peak_stress"],
                     "strain_at_peak": c["strain_at_peak"]})
    if not curves:
        raise ValueError(f"none of the {len(dirs)} directories gives a curve; the first: "
                         f"{reasons[0] if reasons else 'none given'}. Fix: give run "
                         "directories of compression runs (with deck.resolved.toml, "
                         "history.csv and frames)")
    out.mkdir(parents=True, exist_ok=True)
    peaks = np.array([r["peak_stress_Pa"] for r in rows])
    strains = np.array([r["strain_at_peak"] for r in rows])
    stats = {"peak_stress": _stats(peaks), "strain_at_peak": _stats(strains),
             "skipped": skipped}
    hom = None
    if homogeneous is not None:
        hom = compression_curve(homogeneous, wall)
        stats["homogeneous"] = {"peak_stress": hom["peak_stress"],
                                "strain_at_peak": hom["strain_at_peak"]}

    with atomic_path(out / "ucs_samples.csv") as tmp:
        with open(tmp, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=["sample", "peak_stress_Pa",
                                              "strain_at_peak"])
            w.writeheader()
            w.writerows(rows)
    with atomic_path(out / "ucs_statistics.json") as tmp:
        Path(tmp).write_text(json.dumps(stats, indent=2))

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.4, 4.4), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    for k, c in enumerate(curves):
        ax.plot(c["strain"] * 1e3, c["stress"] * 1e-6, color="tab:blue", lw=0.7,
                alpha=0.5, label="heterogeneous samples" if k == 0 else None)
    if hom is not None:
        ax.plot(hom["strain"] * 1e3, hom["stress"] * 1e-6, color="black", lw=2.0,
                label="homogeneous")
    ps = stats["peak_stress"]
    if ps["n"]:
        ax.set_title(f"{ps['n']} samples: peak {ps['mean'] * 1e-6:.1f} MPa, "
                     f"CoV {100 * ps['cov']:.1f} %", fontsize=10)
    ax.set_xlabel("strain [‰]")
    ax.set_ylabel("stress [MPa]")
    ax.set_xlim(left=0)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right", fontsize=8)
    save_figure(fig, out / "ucs_curves.png", 120)
    return stats
