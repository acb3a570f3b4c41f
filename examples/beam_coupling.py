"""Thesis sec. 4.1 (Fig. 4.1): the five beam models side by side.

Runs examples/beam_{fem,penalty,tied,hybrid,sph}.toml (or reuses their
output in out/beam_*/ with --reuse) and writes

* docs/figures/beam_coupling_von_mises.png: the five beams stacked, the
  layer of elements and particles just above the mid-plane z = 0 seen from
  +z, coloured by von Mises stress (like the thesis's Fig. 4.1);
* docs/figures/beam_coupling_reactions.png: the end reaction against time
  (during the ramp it includes the mass damping of the moving beam; the
  static force is the held value after 0.1 s);
* a table (stdout, markdown): end force at 0.5 m and its difference to pure
  FEM, the inflection point (where the centre line has moved half the end
  displacement), the largest deviation of the centre line from pure FEM;
* a second table, the interfaces' smoothness as numbers (issue 53): along
  the top row of items (elements and particles, the row the thesis's
  Fig. 4.1 shows the stress of), the von Mises stress profile against pure
  FEM's within three element sizes of each interface (x = 1.5 and 3.5 m):
  its largest difference (the jump) and the RMS of the difference of the
  second differences (the item-to-item oscillation), both in per cent of
  pure FEM's stress there (:func:`interface_errors`).

    python examples/beam_coupling.py [--reuse] [--models fem,penalty,...]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
#: the thesis's five models
MODELS = ("fem", "penalty", "tied", "hybrid", "sph")
#: every SPH region uses the total-Lagrangian kernel (docs/examples.md)
LABELS = {"fem": "pure FEM (reference)", "penalty": "FEM-SPH-FEM, penalty",
          "tied": "FEM-SPH-FEM, tied", "hybrid": "FEM-SPH-FEM, hybrid",
          "sph": "pure SPH"}


def run(model: str, reuse: bool) -> Path:
    """Run one deck (unless ``reuse`` and its output exists); its output folder."""
    from sphdyn.simulation import run_deck

    out = ROOT / "out" / f"beam_{model}"
    run_deck(ROOT / "examples" / f"beam_{model}.toml", out, reuse=reuse, progress=True)
    return out


def last_frame(out: Path):
    """Particle fields and mesh blocks of the last frame of a run."""
    from sphdyn.io import read_frame, read_frame_meshes

    path = sorted((out / "frames").glob("frame_*.h5"))[-1]
    _, _, fields, _ = read_frame(path)
    return fields, read_frame_meshes(path)


def centre_line(fields, meshes, x_bins: np.ndarray) -> np.ndarray:
    """Mean vertical displacement [m] of the items (nodes and particles) in
    each bin of their initial x: the centre line of the cross-sections."""
    xs, uy = [], []
    for m in meshes.values():
        xs.append(m.points[:, 0] - m.point_data["displacement"][:, 0])
        uy.append(m.point_data["displacement"][:, 1])
    if "displacement" in fields and len(fields["position"]):
        xs.append(fields["position"][:, 0] - fields["displacement"][:, 0])
        uy.append(fields["displacement"][:, 1])
    x, u = np.concatenate(xs), np.concatenate(uy)
    idx = np.digitize(x, x_bins)
    return np.array([u[idx == k].mean() if np.any(idx == k) else np.nan
                     for k in range(1, len(x_bins))])


#: the interfaces of the FEM-SPH-FEM models and the element size [m]
INTERFACES = (1.5, 3.5)
ELEMENT = 5.0 / 160


def top_row_profile(fields, meshes, x_bins: np.ndarray, element: float = ELEMENT
                    ) -> np.ndarray:
    """Von Mises stress [Pa] of the items of the top row (initial y within
    half an element of the top centroids' ``0.125 - element/2``) in the layer
    above the mid-plane (``0 < z0 < element``), averaged per bin of initial
    x (an element and a hybrid particle at one centroid count once each);
    NaN where a bin has none."""
    y_row = 0.125 - 0.5 * element
    xs, vm = [], []
    for m in meshes.values():
        x0 = m.points - m.point_data["displacement"]
        c = x0[m.cells].mean(axis=1)
        sel = (np.abs(c[:, 1] - y_row) < 0.5 * element) & (c[:, 2] > 0) & (c[:, 2] < element)
        xs.append(c[sel, 0])
        vm.append(np.asarray(m.cell_data["von_mises"])[sel])
    if len(fields.get("position", ())):
        x0 = fields["position"] - fields["displacement"]
        sel = ((np.abs(x0[:, 1] - y_row) < 0.5 * element) & (x0[:, 2] > 0)
               & (x0[:, 2] < element))
        xs.append(x0[sel, 0])
        vm.append(fields["von_mises"][sel])
    x, v = np.concatenate(xs), np.concatenate(vm)
    idx = np.digitize(x, x_bins)
    return np.array([v[idx == k].mean() if np.any(idx == k) else np.nan
                     for k in range(1, len(x_bins))])


def interface_errors(profile: np.ndarray, reference: np.ndarray, x: np.ndarray,
                     interfaces=INTERFACES, half_width: float = 3 * ELEMENT
                     ) -> list[tuple[float, float]]:
    """Per interface, (jump, oscillation) of a stress profile against the
    reference's (both on the bin centres ``x`` [m]), in per cent of the
    reference's mean magnitude there (the clamped end's corner stress would
    make a row-wide scale meaningless): the jump is the largest ``|s -
    s_ref|`` within ``half_width`` of the interface, the oscillation the RMS
    of ``D2 s - D2 s_ref`` there, ``D2 s_k = s_(k+1) - 2 s_k + s_(k-1)`` (a
    field that alternates item by item has a large second difference, a
    smooth one almost none)."""
    d2 = np.full_like(profile, np.nan)
    d2[1:-1] = (profile[2:] - 2 * profile[1:-1] + profile[:-2]) - \
        (reference[2:] - 2 * reference[1:-1] + reference[:-2])
    out = []
    for xi in interfaces:
        near = np.abs(x - xi) <= half_width
        scale = np.nanmean(np.abs(reference[near])) / 100.0
        out.append((float(np.nanmax(np.abs(profile[near] - reference[near]))) / scale,
                    float(np.sqrt(np.nanmean(d2[near] ** 2))) / scale))
    return out


def draw(ax, fields, meshes, vmax: float):
    """One beam seen from +z: the layer 0 < z0 < dz, coloured by von Mises."""
    from matplotlib.collections import PolyCollection

    polys, values = [], []
    for m in meshes.values():
        x0 = m.points - m.point_data["displacement"]
        zc = x0[m.cells, 2].mean(axis=1)
        dz = np.ptp(x0[m.cells[0], 2])
        sel = (zc > 0) & (zc < dz)
        for c, v in zip(m.cells[sel], m.cell_data["von_mises"][sel]):
            polys.append(m.points[c[:4], :2])
            values.append(v)
    if len(fields.get("position", ())):
        x = fields["position"]
        x0 = x - fields["displacement"]
        dz = np.min(np.diff(np.unique(np.round(x0[:, 2], 9)))) if len(x) > 1 else 1.0
        sel = (x0[:, 2] > 0) & (x0[:, 2] < dz)
        h = 0.5 * dz
        for p, v in zip(x[sel], fields["von_mises"][sel]):
            polys.append(p[:2] + h * np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]))
            values.append(v)
    pc = PolyCollection(polys, array=np.asarray(values) / 1e6, cmap="jet",
                        edgecolors="none")
    pc.set_clim(0, vmax / 1e6)
    ax.add_collection(pc)
    ax.set_xlim(-0.1, 5.1)
    ax.set_ylim(-0.65, 0.2)
    ax.set_aspect("equal")
    return pc


def main(argv=None) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from sphdyn.io import read_history_csv

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--reuse", action="store_true", help="reuse out/beam_* if present")
    ap.add_argument("--models", default=",".join(MODELS))
    args = ap.parse_args(argv)
    models = [m for m in args.models.split(",") if m]
    outs = {m: run(m, args.reuse) for m in models}
    frames = {m: last_frame(o) for m, o in outs.items()}
    hist = {m: read_history_csv(o / "history.csv") for m, o in outs.items()}

    vmax = max(float(np.max(f[1]["beam"].cell_data["von_mises"])) if f[1]
               else float(np.max(f[0]["von_mises"])) for f in frames.values())
    fig, axes = plt.subplots(len(models), 1, figsize=(9, 1.7 * len(models)), sharex=True)
    axes = np.atleast_1d(axes)
    for ax, m in zip(axes, models):
        pc = draw(ax, *frames[m], vmax)
        ax.set_title(LABELS[m], fontsize=9)
        ax.set_ylabel("y [m]")
    axes[-1].set_xlabel("x [m]")
    fig.colorbar(pc, ax=list(axes), label="von Mises stress [MPa]", shrink=0.8)
    fig.savefig(ROOT / "docs/figures/beam_coupling_von_mises.png", dpi=130)

    # during the ramp the reaction also holds the mass damping of the moving
    # beam (c m v, up to MN at the ramp's middle): only the held end (t > 0.1 s)
    # is the static force, so the reaction is drawn against time
    fig, ax = plt.subplots(figsize=(6, 4))
    for m in models:
        h = hist[m]
        ax.plot(h["time"], -h["moved_reaction_y"] / 1e3, label=LABELS[m])
    ax.axvline(0.1, color="k", lw=0.8, ls="--", label="end of the ramp (0.5 m)")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("end reaction -F_y [kN]")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(ROOT / "docs/figures/beam_coupling_reactions.png", dpi=130)

    bins = np.linspace(0, 5, 41)
    mids = 0.5 * (bins[1:] + bins[:-1])
    ref_line = centre_line(*frames["fem"], bins) if "fem" in frames else None
    print("| model | end force [kN] | vs pure FEM | inflection point x [m] | "
          "largest centre-line deviation from FEM [mm] |")
    print("|---|---|---|---|---|")
    f_ref = -hist["fem"]["moved_reaction_y"][-1] if "fem" in hist else np.nan
    for m in models:
        f = -hist[m]["moved_reaction_y"][-1]
        line = centre_line(*frames[m], bins)
        ok = np.isfinite(line)
        x_inf = float(np.interp(-0.25, line[ok][::-1], mids[ok][::-1]))
        dev = (np.nanmax(np.abs(line - ref_line)) * 1e3 if ref_line is not None
               else np.nan)
        print(f"| {LABELS[m]} | {f / 1e3:.1f} | {100 * (f / f_ref - 1):+.1f} % | "
              f"{x_inf:.3f} | {dev:.1f} |")
    if "fem" in frames:
        bins = np.arange(161) * ELEMENT
        centres = 0.5 * (bins[1:] + bins[:-1])
        ref = top_row_profile(*frames["fem"], bins)
        print()
        print("| model | jump at x = 1.5 m [%] | oscillation at 1.5 m [%] | "
              "jump at x = 3.5 m [%] | oscillation at 3.5 m [%] |")
        print("|---|---|---|---|---|")
        for m in models:
            errs = interface_errors(top_row_profile(*frames[m], bins), ref, centres)
            print(f"| {LABELS[m]} | " + " | ".join(f"{j:.1f} | {o:.1f}" for j, o in errs)
                  + " |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
