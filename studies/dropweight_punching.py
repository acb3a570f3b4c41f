"""What breaks the full 5.0 m drop-weight beam (docs/validation.md, "The full 5.0 m
beam is punched through").

Runs the case ``lozano2017_dropweight_5.0m`` at its full spacing twice with
the stress and both CSCM damages in the frames (``sphdyn validate --reuse``:
what is in OUT already is measured, not run again): to 0.5 ms with a frame
every 25 us (``early``) and to 2 ms with a frame every 250 us (``section``),
about 2 and 7 minutes on 2 cores. Prints

* the contact force's first touch and peak (of these runs and of any
  ``--runs`` directory, e.g. the quick case or the 2.5 m beam);
* the history of the concrete particle nearest (590, 50, 59.4) mm, at
  mid-depth under the impact: pressure, von Mises stress, the ratio
  |J1| / sqrt(3 J2') by which MAT_159 moves its fracture energy from GFS (0,
  shear) to GFC or GFT (1, uniaxial stress), principal stresses, brittle and
  ductile damage, vertical velocity (and, for an element, the largest
  ductile damage variable tau_c so far [sqrt(Pa)] and the rate factor);
* the mid-span section (x 585-595 mm) at 1 and 2 ms: per particle row, the
  mean stress along the beam and along z, brittle and ductile damage; the
  largest and smallest axial force of a bottom and a top bar within 100 mm
  of mid-span;
* for each ``--runs`` directory with a frame at 1 ms, the block under the
  impact damaged 0.75 or more (applied damage, particle rows within 100 mm
  of mid-span and 30 mm of the beam's middle plane): its length and depth;
* for each ``--runs`` directory that went on past 3 ms, the energy the
  model lost per mm of mid-span deflection between 3 and 6, 4 and 8 and
  6 and 10 ms (kinetic energy's fall over the deflection's growth: the
  force that resists the motion, as one number).

With ``--fem`` the same for the beam of hexahedra
(``lozano2017_dropweight_fem_5.0m``: the same concrete meshed, the bars
embedded), its runs ``fem_early`` and ``fem_section`` like ``early`` and
``section`` (about 2 and 6 minutes on one core), read off the elements
(their centroids) instead of the particles.

    PYTHONPATH=src python studies/dropweight_punching.py --out OUT [--fem] [--runs DIR ...]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
FIELDS = '["velocity","damage","damage_brittle","damage_ductile","stress","displacement",' \
         '"material"]'
#: case, t_end, frame interval [s] of each run
RUNS = {"early": ("lozano2017_dropweight_5.0m", "0.0005", "0.000025"),
        "section": ("lozano2017_dropweight_5.0m", "0.002", "0.00025"),
        "fem_early": ("lozano2017_dropweight_fem_5.0m", "0.0005", "0.000025"),
        "fem_section": ("lozano2017_dropweight_fem_5.0m", "0.002", "0.00025")}
TRACE = np.array([0.590, 0.050, 0.0594])  # [m], mid-depth under the impact
SECTION = (0.585, 0.595)  # [m], mid-span


def run(out: Path, name: str) -> Path:
    """The run directory of one variant (run by ``sphdyn validate`` unless done)."""
    case, t_end, every = RUNS[name]
    where = out / name
    subprocess.run([sys.executable, "-m", "sphdyn", "validate", case, "--out", str(where),
                    "--reuse", "--set", f"run.t_end={t_end}", "--set",
                    f"output.every={every}", "--set", f"output.fields={FIELDS}"],
                   check=True, cwd=ROOT, stdout=subprocess.DEVNULL)
    return where / case


def concrete(path: Path) -> tuple[float, dict]:
    """(t [s], the concrete's points) of one frame: the particles of material
    0, or, in a frame with a mesh ``beam``, its elements (at their centroids;
    displacement and velocity the mean of their nodes'); the stress (N, 3, 3)."""
    from sphdyn.io import read_frame, read_frame_meshes

    t, _, fields, _ = read_frame(path)
    beam = read_frame_meshes(path).get("beam")
    if beam is not None:
        cells = beam.cells
        fields = {k: beam.cell_data[k] for k in ("stress", "damage", "damage_brittle",
                                                  "damage_ductile", "tau_c_max",
                                                  "rate_factor") if k in beam.cell_data}
        fields["position"] = beam.points[cells].mean(axis=1)
        for k in ("displacement", "velocity"):
            fields[k] = beam.point_data[k][cells].mean(axis=1)
        fields["material"] = np.zeros(cells.shape[0], dtype=np.int32)
    fields["stress"] = fields["stress"].reshape(-1, 3, 3)
    return t, fields


def frames(d: Path):
    """(t [s], fields) of the concrete (:func:`concrete`) in every frame of run ``d``."""
    from sphdyn.io.frames import list_frames

    for f in list_frames(d):
        yield concrete(f)


def contact(d: Path) -> str:
    """First touch and peak of the drop weight's contact force in run ``d``."""
    from sphdyn.io import read_history_csv
    from sphdyn.validation.measures import contact_force

    h = read_history_csv(d / "history.csv")
    t, f = np.asarray(h["time"]), np.abs(contact_force(h, "rod"))
    k = int(np.argmax(f))
    return (f"first touch {1e3 * t[np.argmax(f > 0)]:.3f} ms, peak {f[k] / 1e3:.0f} kN "
            f"at {1e3 * t[k]:.3f} ms")


def resisting_force(d: Path) -> str:
    """Kinetic energy lost per mid-span deflection over three windows [kN]."""
    from sphdyn.io import read_history_csv

    h = read_history_csv(d / "history.csv")
    t = np.asarray(h["time"])
    ke, u = np.asarray(h["E_kinetic"]), -np.asarray(h["probe_midspan_displacement_z"])
    out = []
    for a, b in ((3e-3, 6e-3), (4e-3, 8e-3), (6e-3, 10e-3)):
        if t[-1] < b:
            continue
        i, j = np.argmin(abs(t - a)), np.argmin(abs(t - b))
        out.append(f"{1e3 * a:.0f}-{1e3 * b:.0f} ms {(ke[i] - ke[j]) / (u[j] - u[i]) / 1e3:.2f} kN")
    return ", ".join(out) if out else "(the run ends before 6 ms)"


def trace(d: Path) -> None:
    """The traced particle's stress and damage, frame by frame."""
    x0 = None
    for t, f in frames(d):
        if x0 is None:
            x0 = f["position"] - f["displacement"]
            conc = f["material"] == 0
            i = int(np.flatnonzero(conc)[np.argmin(np.sum((x0[conc] - TRACE) ** 2, axis=1))])
            print(f"point {i} at {np.round(1e3 * x0[i], 2)} mm")
        s = f["stress"][i] / 1e6
        p = -np.trace(s) / 3.0
        dev = s + p * np.eye(3)
        mises = np.sqrt(1.5 * np.sum(dev * dev))  # sqrt(3 J2')
        # MAT_159's fracture-energy transition reads |J1| / sqrt(3 J2'): 1 in
        # uniaxial stress (GFT or GFC), 0 in pure shear (GFS)
        ratio = abs(3.0 * p) / mises if mises > 0.0 else np.inf
        print(f"  t {1e3 * t:.3f} ms  p {p:6.1f}  von Mises {mises:5.1f}  |J1|/sqrt(3J2') "
              f"{ratio:5.2f}  principal {np.round(np.linalg.eigvalsh(s), 1)} MPa  brittle "
              f"{f['damage_brittle'][i]:.2f}  ductile {f['damage_ductile'][i]:.2f}  "
              f"v_z {f['velocity'][i, 2]:.2f} m/s"
              + (f"  tau_c max {f['tau_c_max'][i]:.1f}, rate factor {f['rate_factor'][i]:.2f}"
                 if "tau_c_max" in f else ""))


def section(d: Path, times=(1e-3, 2e-3)) -> None:
    """The mid-span section's rows at ``times``."""
    for t, f in frames(d):
        if min(abs(t - q) for q in times) > 1e-6:
            continue
        x0 = f["position"] - f["displacement"]
        sel = (f["material"] == 0) & (x0[:, 0] > SECTION[0]) & (x0[:, 0] < SECTION[1])
        print(f"t {1e3 * t:.2f} ms: z [mm], mean sigma_xx, sigma_zz [MPa], brittle, ductile"
              f" (of {sel.sum()} points)")
        for z in np.unique(np.round(x0[sel, 2], 6))[::-1]:
            q = sel & (abs(x0[:, 2] - z) < 1e-6)
            s = f["stress"][q]
            print(f"  {1e3 * z:5.1f} {s[:, 0, 0].mean() / 1e6:7.1f} {s[:, 2, 2].mean() / 1e6:7.1f}"
                  f" {f['damage_brittle'][q].mean():5.2f} {f['damage_ductile'][q].mean():5.2f}")


def bars(path: Path) -> None:
    """Axial force of the bars ``bar_b1`` and ``bar_t1`` within 100 mm of mid-span."""
    from sphdyn.io import read_frame_meshes

    for name, mesh in read_frame_meshes(path).items():
        if name not in ("bar_b1", "bar_t1"):
            continue
        x = mesh.points[mesh.cells].mean(axis=1)[:, 0]
        n = mesh.cell_data["axial_force"][abs(x - TRACE[0]) < 0.1] / 1e3
        print(f"  {name}: axial force {n.min():.1f} to {n.max():.1f} kN (tension > 0)")


def damaged_block(d: Path, t: float = 1e-3) -> str:
    """Length and depth of the concrete damaged >= 0.75 under the impact at ``t``."""
    for time, f in frames(d):
        if abs(time - t) > 1e-6:
            continue
        x0 = f["position"] - f["displacement"]
        q = ((f["material"] == 0) & (f["damage"] >= 0.75) & (abs(x0[:, 0] - TRACE[0]) < 0.1)
             & (abs(x0[:, 1] - TRACE[1]) < 0.03))
        if not q.any():
            return "none"
        lo, hi = 1e3 * x0[q].min(axis=0), 1e3 * x0[q].max(axis=0)
        return (f"x {lo[0]:.0f}-{hi[0]:.0f} mm, z {lo[2]:.0f}-{hi[2]:.0f} mm "
                f"({q.sum()} points)")
    return "(no frame at 1 ms)"


def report(early: Path, mid: Path, runs: list[Path]) -> None:
    """Contact, the traced point, section, bars, damaged block and resisting
    force of the runs ``early`` and ``mid`` (and ``runs``)."""
    from sphdyn.io.frames import list_frames

    for d in [mid, *runs]:
        print(f"{d}: contact {contact(d)}")
    trace(early)
    trace(mid)
    section(mid)
    for f in list_frames(mid)[4::4]:  # 1 and 2 ms
        print(f"bars at {f.name}:")
        bars(f)
    for d in [mid, *runs]:
        print(f"{d}: damaged at 1 ms {damaged_block(d)}")
    for d in runs:
        print(f"{d}: resisting force {resisting_force(d)}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--runs", type=Path, nargs="*", default=[],
                    help="other run directories (a case's folder) to measure too")
    ap.add_argument("--fem", action="store_true",
                    help="the beam of hexahedra instead (the runs fem_early, fem_section)")
    args = ap.parse_args()
    prefix = "fem_" if args.fem else ""
    report(run(args.out, prefix + "early"), run(args.out, prefix + "section"), args.runs)


if __name__ == "__main__":
    main()
