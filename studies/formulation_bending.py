"""Study 1: updated- against total-Lagrangian SPH in bending and near free surfaces.

Two elastic steel cases in plane strain (``run.dimension = 2``), each at two
resolutions (``n`` particles across the thickness) and with three kernel
formulations: updated-Lagrangian without gradient correction (``UL``),
updated-Lagrangian with the Randles-Libersky correction (``UL+corr``,
``sph.correction = true``) and total-Lagrangian (``TL``, which always uses
the corrected reference gradients).

* **Cantilever** (``decks/cantilever.toml.tmpl``): free length L = 100 mm,
  thickness H = 10 mm, clamped by fixed particles at x < 0, released with the
  Euler-Bernoulli first-mode shape as initial velocity (set on the particles
  through the Python API; a deck can now give it as a [body.initial]
  velocity expression, see docs/tensile-instability.md). The first
  bending period is measured from the zero crossings of the mean tip
  displacement and compared with

      f1 = (1.8751^2 / (2 pi L^2)) sqrt(E' I / (rho A)),  E' = E / (1 - nu^2)

  (plane strain, per unit depth A = H, I = H^3/12), and with a Timoshenko
  beam (shear coefficient 5/6 and rotary inertia) solved by finite elements
  here, since L/H = 10 is not very slender.

* **Rod struck end-on** (``decks/rod.toml.tmpl``): L = 100 mm, H = 10 mm,
  striking a rigid wall at v = 1 m/s. In plane strain with free lateral faces
  the long-wave bar speed is the plate speed c = sqrt(E' / rho); the contact
  lasts 2 L / c and the wall stress is sigma = rho c v. Measured: contact
  duration between the crossings of half the theoretical force, and the
  plateau stress = mean wall force per unit depth over the middle half of
  the theoretical contact, divided by H.

Run ``PYTHONPATH=src python studies/formulation_bending.py`` (about 16 min
on one core); it writes ``docs/figures/formulation_bending.csv`` and
``docs/figures/formulation_bending.png`` and prints the table.
"""

from __future__ import annotations

import argparse
import csv
import math
import time
from dataclasses import dataclass
from pathlib import Path
from string import Template

import numpy as np

from sphdyn.build import build_stepper
from sphdyn.deck import loads_deck
from sphdyn.build.model import build_model

HERE = Path(__file__).resolve().parent
FIGURES = HERE.parent / "docs" / "figures"

# steel, plane strain
DENSITY = 7850.0          # kg/m^3
YOUNGS = 200e9            # Pa
POISSON = 0.3
E_PLANE = YOUNGS / (1.0 - POISSON ** 2)          # E' of plane strain
SHEAR = YOUNGS / (2.0 * (1.0 + POISSON))
LENGTH = 0.1              # m, free length of the cantilever and length of the rod
THICKNESS = 0.01          # m
ROD_SPEED = 1.0           # m/s
CLAMP_COLUMNS = 3         # fixed particle columns, more than the 2.4 dx support
BETA1_L = 1.8751040687    # first root of cos(bL) cosh(bL) = -1
TIP_AMPLITUDE = 0.2e-3    # m, target first-mode tip amplitude (0.02 H)

FORMULATIONS = (            # label, sph.formulation, sph.correction
    ("UL", "updated_lagrangian", "false"),
    ("UL+corr", "updated_lagrangian", "true"),
    ("TL", "total_lagrangian", "false"),
)
RESOLUTIONS = (6, 12)       # particles across the thickness


# ------------------------------------------------------------------ theory
def euler_bernoulli_f1() -> float:
    """First bending frequency [Hz] of the clamped-free Euler-Bernoulli beam
    with the plane-strain modulus E' (per unit depth A = H, I = H^3/12)."""
    return BETA1_L ** 2 / (2.0 * math.pi * LENGTH ** 2) * math.sqrt(
        E_PLANE * THICKNESS ** 2 / 12.0 / DENSITY)


def timoshenko_f1(elements: int = 400, shear_factor: float = 5.0 / 6.0) -> float:
    """First frequency [Hz] of the clamped-free Timoshenko beam (bending modulus
    E', shear modulus G, shear coefficient ``shear_factor``, rotary inertia),
    from linear two-node elements with one-point shear integration (free of
    shear locking) and lumped translational and rotary masses; with 400
    elements the discretisation error is far below 0.1 %."""
    le = LENGTH / elements
    area, inertia = THICKNESS, THICKNESS ** 3 / 12.0
    ndof = 2 * (elements + 1)                         # (w, theta) per node
    stiff = np.zeros((ndof, ndof))
    mass = np.zeros(ndof)
    k_bend = E_PLANE * inertia / le * np.array([[0, 0, 0, 0], [0, 1, 0, -1],
                                                [0, 0, 0, 0], [0, -1, 0, 1]])
    b_shear = np.array([-1.0 / le, -0.5, 1.0 / le, -0.5])   # gamma = w' - theta
    k_shear = shear_factor * SHEAR * area * le * np.outer(b_shear, b_shear)
    for e in range(elements):
        dofs = slice(2 * e, 2 * e + 4)
        stiff[dofs, dofs] += k_bend + k_shear
        mass[dofs] += 0.5 * le * DENSITY * np.array([area, inertia, area, inertia])
    free = slice(2, ndof)                             # node 0 clamped
    scale = 1.0 / np.sqrt(mass[free])
    dyn = stiff[free, free] * scale[:, None] * scale[None, :]
    omega2 = np.linalg.eigvalsh(dyn)[0]
    return math.sqrt(omega2) / (2.0 * math.pi)


def mode_shape(x: np.ndarray) -> np.ndarray:
    """Euler-Bernoulli first cantilever mode, normalised to 1 at the tip x = L."""
    b = BETA1_L / LENGTH
    sigma = (math.cosh(BETA1_L) + math.cos(BETA1_L)) / (math.sinh(BETA1_L) + math.sin(BETA1_L))

    def phi(s):
        return np.cosh(b * s) - np.cos(b * s) - sigma * (np.sinh(b * s) - np.sin(b * s))

    return phi(x) / phi(LENGTH)


def plate_wave_speed() -> float:
    """Long-wave speed [m/s] of a plane-strain strip with free faces, sqrt(E'/rho)."""
    return math.sqrt(E_PLANE / DENSITY)


# ------------------------------------------------------------------ runs
@dataclass
class Run:
    """One simulated case: sampled times and the recorded signal."""
    case: str
    n: int
    label: str
    t: np.ndarray
    signal: np.ndarray
    particles: int
    steps: int
    seconds: float


class _Sampler:
    """Stepper monitor recording ``fn(stepper)`` after every step."""

    def __init__(self, fn):
        self.fn, self.t, self.values = fn, [], []

    def after_step(self, s) -> None:
        self.t.append(s.t)
        self.values.append(self.fn(s))


def _deck(template: str, n: int, formulation: str, correction: str, label: str,
          t_end: float) -> str:
    dx = THICKNESS / n
    text = Template((HERE / "decks" / template).read_text())
    return text.substitute(
        label=label, t_end=repr(t_end), formulation=formulation, correction=correction,
        density=repr(DENSITY), youngs_modulus=repr(YOUNGS), poisson=repr(POISSON),
        dx=repr(dx), x_clamp=repr(-CLAMP_COLUMNS * dx), length=repr(LENGTH),
        thickness=repr(THICKNESS), speed=repr(ROD_SPEED))


def _run(case: str, template: str, n: int, form: tuple, t_end: float, prepare,
         signal) -> Run:
    """Build the deck's stepper, let ``prepare(stepper)`` set initial data, step
    to ``t_end`` and sample ``signal(stepper)`` after every step."""
    label, formulation, correction = form
    deck = loads_deck(_deck(template, n, formulation, correction, f"{label}, n = {n}", t_end))
    stepper = build_stepper(deck, build_model(deck))
    prepare(stepper)
    sampler = _Sampler(signal)
    stepper.add_monitor(sampler)
    t0 = time.perf_counter()
    while stepper.t < t_end * (1 - 1e-12):
        stepper.step(t_stop=t_end)
    seconds = time.perf_counter() - t0
    values = np.asarray(sampler.values)
    if not np.all(np.isfinite(values)):
        raise RuntimeError(f"{case} {label} n={n}: non-finite signal")
    return Run(case, n, label, np.asarray(sampler.t), values, stepper.part("sph").kin.n,
               stepper.step_count, seconds)


def run_cantilever(n: int, form: tuple, periods: float = 2.5) -> Run:
    """The cantilever released with the first-mode velocity; signal: mean tip
    displacement u_y of the particle column at the free end."""
    omega = 2.0 * math.pi * euler_bernoulli_f1()
    v_tip = TIP_AMPLITUDE * omega
    t_end = periods / euler_bernoulli_f1()
    tip = None

    def prepare(s):
        nonlocal tip
        p = s.part("sph").kin
        x = p.x0[:, 0]
        free = x > 0.0
        p.v[free, 1] = v_tip * mode_shape(x[free])
        tip = np.flatnonzero(x > LENGTH - THICKNESS / n)

    def signal(s):
        p = s.part("sph").kin
        return float(np.mean(p.x[tip, 1] - p.x0[tip, 1]))

    return _run("cantilever", "cantilever.toml.tmpl", n, form, t_end, prepare, signal)


def run_rod(n: int, form: tuple) -> Run:
    """The rod against the wall; signal: wall force per unit depth [N/m]."""
    t_end = 1.3 * 2.0 * LENGTH / plate_wave_speed()

    def signal(s):
        wall = next(i for i in s.interactions if i.name == "end")
        return float(wall.total[0])

    return _run("rod", "rod.toml.tmpl", n, form, t_end, lambda s: None, signal)


# ------------------------------------------------------------- measurement
def zero_crossings(t: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Times where ``u`` changes sign (linear interpolation), t = 0 excluded."""
    s = np.sign(u)
    i = np.flatnonzero((s[:-1] * s[1:] < 0) & (t[:-1] > 0))
    return t[i] - u[i] * (t[i + 1] - t[i]) / (u[i + 1] - u[i])


def measured_period(run: Run) -> float:
    """Bending period from the zero crossings: two crossings per period."""
    tz = zero_crossings(run.t, run.signal)
    if tz.size < 2:
        raise RuntimeError(f"cantilever {run.label} n={run.n}: fewer than 2 zero crossings")
    return 2.0 * (tz[-1] - tz[0]) / (tz.size - 1)


def rod_pulse(run: Run) -> tuple[float, float]:
    """(contact duration [s], plateau stress [Pa]) of the rod's wall force:
    duration between the up- and down-crossings of half the theoretical force
    rho c v H, plateau = mean force over the middle half of the theoretical
    duration after the up-crossing, divided by H."""
    c = plate_wave_speed()
    f_half = 0.5 * DENSITY * c * ROD_SPEED * THICKNESS
    t, f = run.t, run.signal
    above = f >= f_half
    up = np.flatnonzero(above)[0]
    down = up + np.flatnonzero(~above[up:])[0]

    def cross(i):
        return t[i - 1] + (f_half - f[i - 1]) * (t[i] - t[i - 1]) / (f[i] - f[i - 1])

    t_up, t_down = cross(up), cross(down)
    tau = 2.0 * LENGTH / c
    mid = (t >= t_up + 0.25 * tau) & (t <= t_up + 0.75 * tau)
    return t_down - t_up, float(np.mean(f[mid])) / THICKNESS


# ---------------------------------------------------------------- reporting
def table_rows(runs: list[Run]) -> list[dict]:
    """One row per measured quantity with its theory and relative error."""
    f_eb, f_ti = euler_bernoulli_f1(), timoshenko_f1()
    c = plate_wave_speed()
    rows = []
    for r in runs:
        base = {"case": r.case, "n_across": r.n, "formulation": r.label,
                "particles": r.particles, "steps": r.steps, "seconds": round(r.seconds, 1)}
        if r.case == "cantilever":
            f = 1.0 / measured_period(r)
            rows.append({**base, "quantity": "f1 [Hz]", "measured": f, "theory": f_eb,
                         "error_pct": 100 * (f / f_eb - 1),
                         "error_timoshenko_pct": 100 * (f / f_ti - 1)})
        else:
            duration, stress = rod_pulse(r)
            for q, m, th in (("contact duration [us]", 1e6 * duration, 1e6 * 2 * LENGTH / c),
                             ("plateau stress [MPa]", 1e-6 * stress,
                              1e-6 * DENSITY * c * ROD_SPEED)):
                rows.append({**base, "quantity": q, "measured": m, "theory": th,
                             "error_pct": 100 * (m / th - 1), "error_timoshenko_pct": ""})
    return rows


def write_csv(rows: list[dict], path: Path) -> None:
    """The table as CSV (numbers rounded to 4 significant digits)."""
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        for row in rows:
            w.writerow({k: (f"{v:.4g}" if isinstance(v, float) else v) for k, v in row.items()})


def print_table(rows: list[dict]) -> None:
    """The table as Markdown on stdout."""
    print("| case | n across | formulation | quantity | measured | theory | error | "
          "error vs Timoshenko | particles | steps | s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        ti = r["error_timoshenko_pct"]
        ti = f"{ti:+.1f} %" if ti != "" else "-"
        print(f"| {r['case']} | {r['n_across']} | {r['formulation']} | {r['quantity']} | "
              f"{r['measured']:.4g} | {r['theory']:.4g} | {r['error_pct']:+.1f} % | {ti} | "
              f"{r['particles']} | {r['steps']} | {r['seconds']:.0f} |")


def plot(runs: list[Run], path: Path) -> None:
    """Tip displacement histories (top) and rod wall stress (bottom), one
    column per resolution, with the theoretical curves dashed."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    f_eb = euler_bernoulli_f1()
    c = plate_wave_speed()
    fig, axes = plt.subplots(2, len(RESOLUTIONS), figsize=(11, 7), squeeze=False)
    for col, n in enumerate(RESOLUTIONS):
        ax_c, ax_r = axes[0, col], axes[1, col]
        for r in runs:
            if r.n != n:
                continue
            if r.case == "cantilever":
                ax_c.plot(1e3 * r.t, 1e3 * r.signal, label=r.label)
            else:
                ax_r.plot(1e6 * r.t, 1e-6 * r.signal / THICKNESS, label=r.label)
        t = np.linspace(0, 2.5 / f_eb, 500)
        ax_c.plot(1e3 * t, 1e3 * TIP_AMPLITUDE * np.sin(2 * math.pi * f_eb * t), "k--",
                  lw=0.8, label="Euler-Bernoulli")
        ax_c.set(title=f"cantilever, {n} particles across", xlabel="t [ms]",
                 ylabel="tip displacement [mm]")
        tau, s0 = 2 * LENGTH / c, DENSITY * c * ROD_SPEED
        ax_r.plot(1e6 * np.array([0, 0, tau, tau, 1.3 * tau]), 1e-6 * np.array([0, s0, s0, 0, 0]),
                  "k--", lw=0.8, label="rho c v for 2L/c")
        ax_r.set(title=f"rod on a wall, {n} particles across", xlabel="t [us]",
                 ylabel="wall force / H [MPa]")
        for ax in (ax_c, ax_r):
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=FIGURES, help="directory of the CSV and PNG")
    args = ap.parse_args(argv)
    f_eb, f_ti, c = euler_bernoulli_f1(), timoshenko_f1(), plate_wave_speed()
    print(f"E' = E/(1-nu^2) = {E_PLANE:.4g} Pa, f1 Euler-Bernoulli = {f_eb:.2f} Hz, "
          f"Timoshenko = {f_ti:.2f} Hz; c = sqrt(E'/rho) = {c:.1f} m/s, "
          f"2L/c = {2e6 * LENGTH / c:.2f} us, rho c v = {1e-6 * DENSITY * c * ROD_SPEED:.3f} MPa")
    runs = []
    for n in RESOLUTIONS:
        for form in FORMULATIONS:
            for fn in (run_rod, run_cantilever):
                r = fn(n, form)
                print(f"  {r.case:10s} n={n:2d} {r.label:8s} {r.particles} particles, "
                      f"{r.steps} steps, {r.seconds:.0f} s", flush=True)
                runs.append(r)
    rows = table_rows(runs)
    args.out.mkdir(parents=True, exist_ok=True)
    write_csv(rows, args.out / "formulation_bending.csv")
    plot(runs, args.out / "formulation_bending.png")
    print_table(rows)


if __name__ == "__main__":
    main()
