"""Thesis sec. 6.1 (Figs. 6.1, 6.2): the RC I-girder in three-point bending,
pure FEM against SPH concrete with sublayer bars.

Runs examples/igirder_fem.toml and examples/igirder_sph.toml (or reuses
out/igirder_fem and out/igirder_sph with --reuse) and writes

* docs/figures/igirder.png: the damage of both models at the end (the
  largest damage through the girder's width at each point of its side, on
  the same 10 mm grid: the elements' centres are the particles), and the
  force-displacement curves (Fig. 6.2): the sum of the support reactions
  against the prescribed mid-span displacement;
* a table (stdout, markdown): peak force, its displacement, the force at
  fixed displacements and the largest difference of the two curves up to
  the peak, the bars' largest axial force, steps, wall time.

With ``--variants`` it also runs variants of the SPH model (deck overrides
of :data:`VARIANTS`: the sublayer particles coupling only; a mass ratio of
0.25; the particles with the split steel's full 3D stress; corrected kernel
gradients) and of the FEM reference (:data:`FEM_VARIANTS`: selective-reduced
hexes; one-point hexes of 5 mm, 35 minutes alone) into out/igirder_<variant>;
variants found there are drawn dashed (dotted: FEM) and listed in the table,
whose differences are taken to each FEM reference found. Each drawing keeps
its curves in docs/figures/igirder_curves.csv; with ``--reuse`` (which runs
nothing, ``--variants`` or not) a variant whose run is gone or unfinished is
drawn from there (the 5 mm FEM girder takes 35 minutes to rerun).

The curves are averaged over a sliding window of 0.5 ms (about a tenth of
the first bending period) before they are compared: the load rises in
32 ms (six periods), so both carry an inertial ripple, which the window
smooths. Each crack also sets the girder ringing in its first bending mode
(period 5.4 ms), which at this rate moves the FEM girders' own curves by
10-13 % of their peak against each other (5 against 10 mm elements, half
the rate); the *quasi-static* curves (:func:`quasi_static`) are the same
averaged over that period, as reactions from an explicit run of a static
test are filtered, and the table gives the differences of both.

``--curves`` runs nothing: it draws docs/figures/igirder_curves.png (the
curves as run and quasi-static) from the saved curves and the finished runs
in out/ and prints the differences.

    python examples/igirder.py [--reuse] [--variants] [--curves]
"""

from __future__ import annotations

import argparse
import json
import tomllib
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
MODELS = ("fem", "sph")
DX = 0.01  # element size = particle spacing [m]
WINDOW = 0.5e-3  # averaging window of the curves [s]
#: the uncracked girder's first bending period [s] (igirder_fem.toml): the
#: quasi-static curves are averaged over it (:func:`quasi_static`)
FIRST_MODE = 5.4e-3
RAMP_TIME = 32e-3  # the decks' load ramp [s] (the _slow variants: 64 ms)
DEPTH = 8e-3  # the decks' prescribed mid-span displacement [m]
BARS = ("bar_b1", "bar_b2", "bar_t1", "bar_t2")
#: variants of igirder_sph.toml: label and [mesh.sublayer] overrides of every bar
VARIANTS = {
    "sph_none": ("SPH, particles coupling only (stiffness none)",
                 ['mesh.{bar}.sublayer.stiffness="none"']),
    "sph_r025": ("SPH, axial, mass ratio 0.25", ["mesh.{bar}.sublayer.mass_ratio=0.25"]),
    "sph_split": ("SPH, particles of the split steel in 3D (stiffness split)",
                  ['mesh.{bar}.sublayer.stiffness="split"']),
    # kernel gradients corrected: the flanges' free faces carry their share of
    # the bending (78 % of the FEM girders' elastic force without, 93 % with)
    "sph_corr": ("SPH, axial, corrected kernel gradients", ["sph.correction=true"]),
    # half the loading rate, as fem_slow: the fair comparison with that reference
    "sph_slow": ("SPH, axial, the load ramped over 64 ms (half the rate)",
                 ['run.t_end="64 ms"', 'boundary.2.ramp_time="64 ms"']),
    # the particles' fracture-energy length dx, as before 2026-11-27: an SPH crack
    # softens two particle layers, so the concrete dissipated twice G_F per crack
    "sph_band1": ("SPH, axial, crack band 1 dx (twice the fracture energy)",
                  ["sph.crack_band=1"]),
    # the particles 1.5x finer (dx = 20/3 mm, six layers through a flange; the
    # bars' trusses as long): how much of the difference to FEM is resolution
    "sph_fine": ("SPH, axial, dx 6.67 mm (89,100 particles)",
                 [f"body.girder.dx={0.02 / 3!r}",
                  f"mesh.{{bar}}.line.element_length={0.02 / 3!r}"]),
}
#: variants of igirder_fem.toml: label and overrides (the reference's own spread)
FEM_VARIANTS = {
    "fem_sr": ("pure FEM, selective-reduced hexes", ['mesh.0.integration="selective_reduced"']),
    # the mesh halved (201,600 hexes, the bars' trusses 5 mm): which reference converges
    "fem_5mm": ("pure FEM, one-point hexes of 5 mm",
                ['mesh.0.prism.element_size="5 mm"'] +
                [f'mesh.{k}.line.element_length="5 mm"' for k in range(1, 5)]),
    # half the loading rate: how much of the dip after the first crack is
    # the girder ringing (inertia) rather than its static response
    "fem_slow": ("pure FEM, the load ramped over 64 ms (half the rate)",
                 ['run.t_end="64 ms"', 'boundary.2.ramp_time="64 ms"']),
}


def finished(out: Path) -> bool:
    """The run in ``out`` reached its end (an interrupted one leaves a summary too)."""
    summary = out / "summary.json"
    return summary.exists() and json.loads(summary.read_text())["status"] == "completed"


def run(model: str, reuse: bool) -> Path:
    """Run one deck or variant (unless ``reuse`` finds its output); its output folder."""
    from sphdyn.simulation import run_deck

    out = ROOT / "out" / f"igirder_{model}"
    if not (reuse and finished(out)):
        if model in VARIANTS:
            overrides = [o.format(bar=b) for o in VARIANTS[model][1] for b in BARS]
            run_deck(ROOT / "examples" / "igirder_sph.toml", out, overrides=overrides,
                     progress=True)
        elif model in FEM_VARIANTS:
            run_deck(ROOT / "examples" / "igirder_fem.toml", out,
                     overrides=FEM_VARIANTS[model][1], progress=True)
        else:
            run_deck(ROOT / "examples" / f"igirder_{model}.toml", out, progress=True)
    return out


def curve(out: Path) -> tuple[np.ndarray, np.ndarray]:
    """Prescribed mid-span displacement [m] (the deck's smooth ramp) and the
    supports' reaction [N] (sum of both, upwards), averaged over :data:`WINDOW`."""
    from sphdyn.interactions.nodal import ramp
    from sphdyn.io import read_history_csv

    h = read_history_csv(out / "history.csv")
    t = h["time"]
    deck = tomllib.loads((out / "deck.resolved.toml").read_text())
    load = next(b for b in deck["boundary"] if b["set"] == "load")
    depth, ramp_time = -load["displacement"][2], load["ramp_time"]
    force = h["support_left_reaction_z"] + h["support_right_reaction_z"]
    d = np.array([depth * ramp(ti, ramp_time, "smooth") for ti in t])
    return d, moving_average(force, WINDOW / np.median(np.diff(t)))


def moving_average(y: np.ndarray, width: float) -> np.ndarray:
    """``y`` averaged over ``width`` samples (rounded) centred on each; the
    ends, less than half a window long, as they are."""
    k = max(1, int(round(width)))
    out = y.copy()
    out[k // 2: k // 2 + y.size - k + 1] = np.convolve(y, np.ones(k) / k, mode="valid")
    return out


#: the curves of the last drawing, so a later one can redraw runs whose
#: output is gone (``--reuse``): model, displacement [m], force [N]
CURVES = ROOT / "docs" / "figures" / "igirder_curves.csv"


def save_curves(curves: dict) -> None:
    """Write every curve to :data:`CURVES`, resampled every 0.02 mm."""
    lines = ["model,displacement_m,force_N"]
    for model, (d, f) in curves.items():
        # the grid's points up to d's last (a saved curve saved again stays whole)
        grid = 2e-5 * np.arange(int(np.floor(d.max() / 2e-5 + 1e-6)) + 1)
        lines += [f"{model},{x:.6e},{y:.6e}" for x, y in zip(grid, np.interp(grid, d, f))]
    CURVES.write_text("\n".join(lines) + "\n")


def saved_curve(model: str) -> tuple[np.ndarray, np.ndarray] | None:
    """A model's curve from :data:`CURVES`, or None."""
    if not CURVES.exists():
        return None
    rows = [r.split(",") for r in CURVES.read_text().splitlines()[1:]]
    pts = np.array([(float(a), float(b)) for m, a, b in rows if m == model])
    return (pts[:, 0], pts[:, 1]) if pts.size else None


def side_damage(out: Path, model: str) -> np.ndarray:
    """(nz, nx) largest damage across the width at each point of the side, last frame."""
    import h5py

    from sphdyn.analysis.fragments import side_view_max
    from sphdyn.io import read_frame_meshes

    last = sorted((out / "frames").glob("frame_*.h5"))[-1]
    if model == "fem":
        mesh = read_frame_meshes(last)["girder"]
        x0 = (mesh.points - mesh.point_data["displacement"])[mesh.cells].mean(axis=1)
        d = mesh.cell_data["damage"]
    else:
        with h5py.File(last, "r") as f:
            x0 = f["position"][:] - f["displacement"][:]
            d = f["damage"][:]
            concrete = f["material"][:] == 0  # not the bars' sublayer particles
        x0, d = x0[concrete], d[concrete]
    return side_view_max(x0, d, DX)


def table_row(model: str, out: Path, d: np.ndarray, f: np.ndarray) -> tuple:
    """(model, peak force [N], its displacement [m], the tension trusses' largest
    force [N], steps, wall [s], energy error) of one run with curve ``d, f``."""
    from sphdyn.io import read_history_csv

    h = read_history_csv(out / "history.csv")
    bars = max(h[f"bar_{b}_axial_force_max"].max() for b in ("b1", "b2"))
    summary = json.loads((out / "summary.json").read_text())
    return (model, f.max(), d[np.argmax(f)], bars, summary["steps"],
            summary["wall_seconds"], summary["energy_error_max_rel"])


def ramp_time(model: str) -> float:
    """The load's ramp time of a model [s]: the deck's, or a variant's override."""
    from sphdyn.deck.units import TIME, to_si

    overrides = {**VARIANTS, **FEM_VARIANTS}.get(model, ("", []))[1]
    for o in overrides:
        if o.startswith("boundary.2.ramp_time="):
            return to_si(o.split("=", 1)[1].strip('"'), TIME)
    return RAMP_TIME


def quasi_static(curve: tuple, ramp: float) -> tuple[np.ndarray, np.ndarray]:
    """A curve ``(d, F)`` of :func:`curve` averaged over :data:`FIRST_MODE` in
    time (``ramp`` the load's ramp time [s]: d(t) is the deck's smooth ramp),
    which takes out the girder's ringing in its first bending mode (each
    crack sets it ringing; at the decks' rate it moves the FEM girders'
    curves by up to 10-13 % of their peak against each other): the
    quasi-static force-displacement response, as reactions from an explicit
    run of a static test are filtered. The first and last half-windows stay
    as they are."""
    from sphdyn.interactions.nodal import ramp as ramp_value

    d, f = curve
    t = np.linspace(0.0, ramp, 8001)
    d_t = DEPTH * np.array([ramp_value(ti, ramp, "smooth") for ti in t])  # d at t
    d_t = d_t[d_t <= d.max()]
    return d_t, moving_average(np.interp(d_t, d, f), FIRST_MODE / (t[1] - t[0]))


def worst_difference(ref: tuple, other: tuple) -> float:
    """Largest |F - F_ref| / max F_ref over 40 displacements from 0.25 mm to the
    reference's peak (curves ``(d, F)`` of :func:`curve`)."""
    d_f, f_f = ref
    grid_d = np.linspace(0.25e-3, d_f[np.argmax(f_f)], 40)
    ff = np.interp(grid_d, d_f, f_f)
    return float(np.max(np.abs(np.interp(grid_d, *other) - ff) / ff.max()))


def draw_curves(fig, cells, curves: dict, quasi: dict) -> None:
    """The force-displacement curves as run and quasi-static, in the
    gridspec ``cells`` (two) of ``fig``."""
    labels = {"fem": "pure FEM (one-point hexes)", "sph": "SPH + sublayer (axial, ratio 0.5)",
              **{k: v[0] for k, v in {**FEM_VARIANTS, **VARIANTS}.items()}}
    for cell, shown, title in (
            (cells[0], curves, f"as run (averaged over {1e3 * WINDOW:.1f} ms)"),
            (cells[1], quasi, "quasi-static: averaged over the first bending period "
                              f"({1e3 * FIRST_MODE:.1f} ms)")):
        ax = fig.add_subplot(cell)
        for model, (d, f) in shown.items():
            style = "--" if model in VARIANTS else (":" if model in FEM_VARIANTS else "-")
            ax.plot(1e3 * d, 1e-3 * f, style, label=labels[model])
        ax.set_title(title)
        ax.set_xlabel("mid-span displacement [mm]")
        ax.set_ylabel("support reactions [kN]")
        ax.grid(alpha=0.3)
    ax.legend(fontsize="small", ncol=2)


def print_differences(curves: dict, quasi: dict, rows: list) -> None:
    """The table of the runs (``rows`` of :func:`table_row`), the differences
    of the other curves (drawn from :data:`CURVES`) and the forces at fixed
    displacements (stdout)."""
    refs = [r for r in ("fem", *FEM_VARIANTS) if r in curves]

    def diff(r, m):
        return (f"{100 * worst_difference(curves[r], curves[m]):.1f} %; "
                f"{100 * worst_difference(quasi[r], quasi[m]):.1f} %")

    print("| model | peak force [kN] | at displacement [mm] | truss force max [kN] | "
          + "".join(f"largest difference to {r} up to its peak (as run; quasi-static) | "
                    for r in refs)
          + "steps | wall [s] | energy error (max, rel.) |")
    print("|---|---|---|---|" + "---|" * len(refs) + "---|---|---|")
    for model, fmax, dmax, bars, steps, wall, err in rows:
        print(f"| {model} | {1e-3 * fmax:.1f} | {1e3 * dmax:.2f} | {1e-3 * bars:.1f} | "
              + "".join(f"{diff(r, model)} | " for r in refs)
              + f"{steps} | {wall:.0f} | {err:.4f} |")
    print("\n(the difference in % of the reference's peak force, up to its peak)")
    saved = [m for m in curves if m not in {r[0] for r in rows}]
    if saved:
        print("\ncurves of earlier runs (docs/figures/igirder_curves.csv), largest "
              "difference up to the reference's peak (as run; quasi-static):")
        for model in saved:
            print(f"  {model}: " + ", ".join(f"to {r} {diff(r, model)}"
                                             for r in refs if r != model))
    for dd in (1e-3, 2e-3, 4e-3, 6e-3):
        print(f"  at {1e3 * dd:.0f} mm: " + ", ".join(
            f"{m} {1e-3 * np.interp(dd, *curves[m]):.1f} kN" for m in curves))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reuse", action="store_true", help="reuse out/igirder_*")
    ap.add_argument("--variants", action="store_true", help="also run the SPH variants")
    ap.add_argument("--curves", action="store_true",
                    help="run nothing: draw docs/figures/igirder_curves.png from the saved "
                         "curves and the finished runs in out/")
    a = ap.parse_args()

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figures = ROOT / "docs" / "figures"
    figures.mkdir(parents=True, exist_ok=True)
    curves, rows = {}, []
    if a.curves:
        for name in (*MODELS, *FEM_VARIANTS, *VARIANTS):
            out = ROOT / "out" / f"igirder_{name}"
            if finished(out):
                curves[name] = curve(out)
                rows.append(table_row(name, out, *curves[name]))
            elif (saved := saved_curve(name)) is not None:
                curves[name] = saved
        quasi = {m: quasi_static(c, ramp_time(m)) for m, c in curves.items()}
        fig = plt.figure(figsize=(12, 8), layout="constrained")
        grid = fig.add_gridspec(2, 1)
        draw_curves(fig, (grid[0], grid[1]), curves, quasi)
        fig.suptitle("RC I-girder in three-point bending (thesis 6.1): force-displacement")
        fig.savefig(figures / "igirder_curves.png", dpi=110)
        save_curves(curves)
        print_differences(curves, quasi, rows)
        return

    fig = plt.figure(figsize=(12, 12), layout="constrained")
    grid = fig.add_gridspec(4, 1, height_ratios=[1, 1, 1.6, 1.6])
    for k, model in enumerate(MODELS):
        out = run(model, a.reuse)
        img = side_damage(out, model)
        ax = fig.add_subplot(grid[k])
        im = ax.imshow(img, origin="lower", cmap="inferno_r", vmin=0, vmax=1,
                       extent=(0, img.shape[1] * DX * 1e3, 0, img.shape[0] * DX * 1e3))
        ax.set_title({"fem": "pure FEM (hex8 CSCM, embedded truss bars)",
                      "sph": "SPH concrete with sublayer bars (mass ratio 0.5, "
                             "stiffness axial)"}[model])
        ax.set_ylabel("z [mm]")
        curves[model] = curve(out)
        rows.append(table_row(model, out, *curves[model]))
    fig.axes[-1].set_xlabel("x [mm]")
    fig.colorbar(im, ax=fig.axes[:2], shrink=0.8, label="damage (max across the width)")
    for name in (*FEM_VARIANTS, *VARIANTS):
        if finished(ROOT / "out" / f"igirder_{name}") or (a.variants and not a.reuse):
            out = run(name, not a.variants or a.reuse)  # --reuse never runs one
            curves[name] = curve(out)
            rows.append(table_row(name, out, *curves[name]))
        elif a.reuse and (saved := saved_curve(name)) is not None:  # its run is gone
            curves[name] = saved
    quasi = {m: quasi_static(c, ramp_time(m)) for m, c in curves.items()}
    draw_curves(fig, (grid[2], grid[3]), curves, quasi)
    fig.suptitle("RC I-girder in three-point bending (thesis 6.1): damage at 8 mm and "
                 "force-displacement")
    fig.savefig(figures / "igirder.png", dpi=110)
    save_curves(curves)
    print_differences(curves, quasi, rows)


if __name__ == "__main__":
    main()
