"""Thesis ch. 8 (Figs. 8.3-8.5): a 500 kg ram dropped 0.95 m on an RC beam.

Runs examples/dropweight_coarse.toml (dx 12 mm) without and with the CSCM
rate effects into out/dropweight_coarse and out/dropweight_coarse_rate
(``--full``: also examples/dropweight.toml, dx 6 mm, into out/dropweight;
``--reuse`` only reads), and writes

* docs/figures/dropweight.png: the gauges over time, the longitudinal strain
  on the top surface beside the ram (Fig. 8.3) and the vertical
  displacement at mid-span, mid-height (Fig. 8.4), of every run found; the
  damage at the end of the first run (Fig. 8.5): of the side face's layer
  of particles (what a photo shows) and the largest across the beam's
  width at each point of its side;
* a table (stdout, markdown): the peak displacement, the strain of largest
  magnitude, when they occur, the largest sum of the support reactions, steps, wall time, energy
  error.

``--gravity`` runs the gravity variant instead (out/dropweight_coarse_gravity):
the coarse model with ``run.gravity`` on and the ram released at rest 0.1 mm
above where its particles touch the beam's (it falls onto the beam after
sqrt(2 h / g) = 4.5 ms), 8 ms; writes docs/figures/dropweight_gravity.png: the ram's fall
against h(t) = g t^2 / 2, and the support reactions against the weight.

    python examples/dropweight.py [--reuse] [--full | --gravity] [--variants]

``--reuse`` draws the runs found in out/ and runs nothing. Runs of the decks
as they were before their stirrups (:data:`EARLIER`), if found in out/, are
drawn dashed for comparison; ``--variants`` also runs :data:`VARIANTS` (the
coarse deck with the sublayer's stiffness ``"axial"``, 20-30 minutes), drawn
dotted whenever found in out/. A second table gives how far the damage
spreads beyond the middle of the beam (:func:`damage_spread`).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
#: run name: (deck, overrides, label)
RUNS = {
    "dropweight_coarse": ("dropweight_coarse.toml", [], "dx 12 mm, no rate effects"),
    "dropweight_coarse_rate": ("dropweight_coarse.toml", ["material.0.rate_effects=true"],
                               "dx 12 mm, rate effects"),
    "dropweight": ("dropweight.toml", [], "dx 6 mm, no rate effects"),
}
#: the sublayer meshes of the decks (bars and stirrups)
SUBLAYERS = ("bar_b1", "bar_b2", "bar_t1", "bar_t2", "stirrups")
#: variants run with ``--variants`` and drawn dotted when found in out/:
#: run name: (deck, overrides, label)
VARIANTS = {
    # the sublayer particles' stress along the bar only (the I-girder's deck):
    # how much of the damage inside the beam is the split particles' bond zone
    "dropweight_coarse_axial": ("dropweight_coarse.toml",
                                [f'mesh.{m}.sublayer.stiffness="axial"' for m in SUBLAYERS],
                                "dx 12 mm, sublayer axial"),
}
#: runs drawn dashed when found in out/ but not made by this script: the coarse
#: deck as it was before its stirrups (git show 829f472:examples/dropweight_coarse.toml)
EARLIER = {
    "dropweight_coarse_nostirrups": "dx 12 mm, no stirrups (decks of 829f472)",
    "dropweight_coarse_rate_nostirrups": "dx 12 mm, rate effects, no stirrups (829f472)",
}


def concrete_damage(out: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """The concrete particles' initial positions (N, 3) [m] and damage (N,) at
    the last frame, the mask of the side face's layer (the particles a photo
    of the specimen shows, thesis Figs. 8.2 and 8.5) and the lattice
    spacing [m]."""
    import h5py

    last = sorted((out / "frames").glob("frame_*.h5"))[-1]
    with h5py.File(last, "r") as f:
        x0 = f["position"][:] - f["displacement"][:]
        d = f["damage"][:]
        concrete = f["material"][:] == 0  # not the bars' sublayer particles
    x0, d = x0[concrete], d[concrete]
    dx = float(np.min(np.diff(np.unique(np.round(x0[:, 2], 6)))))
    return x0, d, x0[:, 1] < x0[:, 1].min() + 0.5 * dx, dx


def side_damage(out: Path, face: bool) -> tuple[np.ndarray, float]:
    """(nz, nx) damage of the concrete seen from the side at the last frame:
    of the side face's layer of particles (``face``), or the largest across
    the width; and the lattice spacing [m]."""
    from sphdyn.analysis.fragments import side_view_max

    x0, d, layer, dx = concrete_damage(out)
    if face:
        x0, d = x0[layer], d[layer]
    return side_view_max(x0, d, dx), dx


def damage_spread(out: Path) -> tuple[float, ...]:
    """How far the damage spreads beyond the middle (x = 600-900 mm) at the
    end, over the concrete particles there: of the side face's layer, the
    fractions cracked through (damage > 0.9) and nearly intact (< 0.1); of
    all of them (the face and the 12 layers behind it), the mean and the same
    two fractions; and the mean over the overhangs beyond the supports
    (x < 100 or > 1400 mm, where the moment is nil)."""
    x0, d, layer, _ = concrete_damage(out)
    outside = (x0[:, 0] < 0.6) | (x0[:, 0] > 0.9)
    face, inner = d[outside & layer], d[outside]
    overhangs = d[(x0[:, 0] < 0.1) | (x0[:, 0] > 1.4)]
    return (float(np.mean(face > 0.9)), float(np.mean(face < 0.1)), float(inner.mean()),
            float(np.mean(inner > 0.9)), float(np.mean(inner < 0.1)), float(overhangs.mean()))


#: the gravity variant: the ram at rest, 0.1 mm above where its particles
#: first touch the beam's (particle contact at (s_i + s_j)/2 = 12 mm centre
#: to centre: after 5.608 mm of fall from the decks' position, so its
#: head's centre 5.508 mm lower), g on, 8 ms
GRAVITY = ["run.gravity=[0, 0, -9.81]", "body.ram.velocity=[0, 0, 0]",
           "body.ram.geometry.centre=[0.75, 0.078, 0.298492]", "run.t_end=8e-3",
           "output.every=2e-4", "output.history_every=5"]
G = 9.81
RAM = 3  # the ram's material index in the decks (ram_steel)


def masses(out: Path) -> tuple[float, float]:
    """The mass of a run's whole model (particles and mesh nodes) and of its
    ram [kg], from its resolved deck."""
    from sphdyn.build import build_stepper
    from sphdyn.deck import load_deck

    stepper = build_stepper(load_deck(out / "deck.resolved.toml"))
    p = stepper.parts[0].p
    return (float(sum(part.kin.m.sum() for part in stepper.parts)),
            float(p.m[p.mat == RAM].sum()))


def gravity(reuse: bool) -> None:
    """The gravity variant (module docstring): its run and figure."""
    import h5py
    import matplotlib.pyplot as plt

    from sphdyn.io import read_history_csv
    from sphdyn.io.hdf5 import read_frame_header
    from sphdyn.simulation import run_deck

    out = ROOT / "out" / "dropweight_coarse_gravity"
    run_deck(ROOT / "examples" / "dropweight_coarse.toml", out, GRAVITY, reuse=reuse,
             progress=True)
    times, fall = [], []
    for path in sorted((out / "frames").glob("frame_*.h5")):
        with h5py.File(path, "r") as f:
            ram = f["material"][:] == RAM
            fall.append(f["displacement"][:][ram, 2].mean())
        times.append(read_frame_header(path)[0])
    times, fall = np.array(times), np.array(fall)
    h = read_history_csv(out / "history.csv")
    reaction = h["base_left_reaction_z"] + h["base_right_reaction_z"]
    weight, ram_mass = masses(out)
    fig, (ax_f, ax_r) = plt.subplots(2, 1, figsize=(9, 7), sharex=True,
                                     layout="constrained")
    ax_f.plot(1e3 * times, -1e3 * fall, "o", ms=3, label="ram (mean of its particles)")
    t = np.linspace(0.0, times[-1], 200)
    ax_f.plot(1e3 * t, 1e3 * 0.5 * G * t ** 2, "--", label="free fall g t^2 / 2")
    ax_f.axhline(0.1, color="0.5", lw=0.8, label="the 0.1 mm gap to contact")
    ax_f.set_ylabel("fall [mm]")
    ax_r.plot(1e3 * h["time"], 1e-3 * reaction, label="support reactions (sum)")
    ax_r.axhline(1e-3 * G * weight, color="k", ls="--",
                 label=f"total weight ({weight:.0f} kg: ram, beam, bars, supports)")
    ax_r.axhline(1e-3 * G * (weight - ram_mass), color="0.4", ls=":",
                 label=f"the weight without the ram ({ram_mass:.0f} kg)")
    ax_r.set_ylabel("force [kN]")
    ax_r.set_xlabel("time [ms]")
    for ax in (ax_f, ax_r):
        ax.grid(alpha=0.3)
        ax.legend()
    fig.suptitle("Gravity variant of the coarse drop-weight model: the ram released "
                 "at rest 0.1 mm above the beam")
    fig.savefig(ROOT / "docs" / "figures" / "dropweight_gravity.png", dpi=110)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reuse", action="store_true", help="only read out/dropweight*")
    ap.add_argument("--full", action="store_true", help="also run the dx 6 mm deck")
    ap.add_argument("--gravity", action="store_true",
                    help="the gravity variant instead (module docstring)")
    ap.add_argument("--variants", action="store_true",
                    help="also run the variants of VARIANTS (the sublayer axial)")
    a = ap.parse_args()

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from sphdyn.io import read_history_csv

    if a.gravity:
        gravity(a.reuse)
        return
    from sphdyn.simulation import run_deck, run_examples

    outs = run_examples(ROOT, RUNS, "dropweight", reuse=a.reuse, include_full=a.full)
    labels = {name: RUNS[name][2] for name in outs}
    for name, (deck, overrides, label) in VARIANTS.items():
        if a.variants and not a.reuse:
            run_deck(ROOT / "examples" / deck, ROOT / "out" / name, overrides, reuse=True,
                     progress=True)
        if (ROOT / "out" / name / "summary.json").exists():
            outs[name], labels[name] = ROOT / "out" / name, label
    for name, label in EARLIER.items():
        if (ROOT / "out" / name / "summary.json").exists():
            outs[name], labels[name] = ROOT / "out" / name, label
    fig = plt.figure(figsize=(11, 12.5), layout="constrained")
    grid = fig.add_gridspec(4, 1, height_ratios=[1, 1, 0.8, 0.8])
    ax_s, ax_d = fig.add_subplot(grid[0]), fig.add_subplot(grid[1])
    rows = []
    for name, out in outs.items():
        strain = read_history_csv(out / "gauges" / "top_strain.csv")
        disp = read_history_csv(out / "gauges" / "midspan.csv")
        label = labels[name]
        style = "--" if name in EARLIER else (":" if name in VARIANTS else "-")
        ax_s.plot(1e3 * strain["time"], 1e6 * strain["strain"], style, label=label)
        ax_d.plot(1e3 * disp["time"], 1e3 * disp["displacement_z"], style, label=label)
        h = read_history_csv(out / "history.csv")
        summary = json.loads((out / "summary.json").read_text())
        k, j = np.argmin(disp["displacement_z"]), np.argmax(np.abs(strain["strain"]))
        rows.append((label, disp["displacement_z"][k], disp["time"][k],
                     strain["strain"][j], strain["time"][j],
                     (h["base_left_reaction_z"] + h["base_right_reaction_z"]).max(),
                     summary["steps"], summary["wall_seconds"],
                     summary["energy_error_max_rel"], summary["status"]))
    ax_s.set_ylabel("top-surface strain [µm/m]")
    ax_s.set_title("Longitudinal strain on the top surface, x = 550-650 mm (thesis Fig. 8.3)")
    ax_d.set_ylabel("displacement [mm]")
    ax_d.set_xlabel("time [ms]")
    ax_d.set_title("Vertical displacement at mid-span, mid-height (thesis Fig. 8.4)")
    for ax in (ax_s, ax_d):
        ax.grid(alpha=0.3)
        ax.legend()
    first = next(iter(outs))
    for row, face, what in ((2, True, "the side face, as a photo"),
                            (3, False, "the largest across the width")):
        img, dx = side_damage(outs[first], face)
        ax = fig.add_subplot(grid[row])
        im = ax.imshow(img, origin="lower", cmap="inferno_r", vmin=0, vmax=1,
                       extent=(0, img.shape[1] * dx * 1e3, 0, img.shape[0] * dx * 1e3))
        ax.set_title(f"Damage at the end, {labels[first]}: {what} (thesis Fig. 8.5)")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("z [mm]")
        fig.colorbar(im, ax=ax, shrink=0.8, label="damage")
    fig.suptitle("500 kg ram dropped 0.95 m (4.32 m/s) on an RC beam (thesis ch. 8)")
    figures = ROOT / "docs" / "figures"
    figures.mkdir(parents=True, exist_ok=True)
    fig.savefig(figures / "dropweight.png", dpi=110)

    print("| model | peak displacement [mm] | at [ms] | largest top strain [µm/m] | at [ms] "
          "| support reactions max [kN] | steps | wall [s] | energy error (max, rel.) "
          "| status |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for label, d, td, e, te, f, steps, wall, err, status in rows:
        print(f"| {label} | {1e3 * d:.2f} | {1e3 * td:.2f} | {1e6 * e:.0f} | "
              f"{1e3 * te:.2f} | {1e-3 * f:.1f} | {steps} | {wall:.0f} | {err:.4f} | "
              f"{status} |")
    print("\n| model (particles outside x = 600-900 mm) | face: damage > 0.9 | face: < 0.1 "
          "| all: mean | all: > 0.9 | all: < 0.1 | overhangs: mean |")
    print("|---|---|---|---|---|---|---|")
    for name, out in outs.items():
        print(f"| {labels[name]} | " + " | ".join(f"{v:.2f}" for v in damage_spread(out))
              + " |")


if __name__ == "__main__":
    main()
