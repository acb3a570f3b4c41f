"""Material-point driver: run any registered model along a load path.

One material point is updated with the model's group kernel (common
signature, :data:`sphdyn.materials.base.KERNEL_SIGNATURE_DOC`) under a
symmetric velocity gradient ``L = D = d_eps/dt``. Each of the six strain
components (``xx, yy, zz, xy, yz, xz``, tensor shear) is either *strain
controlled* (increment prescribed) or *stress controlled* (target stress
prescribed); the unknown strain increments of the stress-controlled
components are found per step by Newton iteration with a finite-difference
Jacobian, re-running the update from the saved start-of-step state.

Paths (tension positive; ``strain`` is the magnitude of the controlling
strain):

=====================  ===============================================
uniaxial-compression   eps_xx -> -strain, sigma_yy = sigma_zz = 0
uniaxial-tension       eps_xx -> +strain, sigma_yy = sigma_zz = 0
hydrostatic            eps_xx = eps_yy = eps_zz -> -strain/3 (volumetric strain -strain)
triaxial               stress ramp to -confinement (all three), then
                       eps_xx further by -strain with sigma_yy = sigma_zz = -confinement
shear                  eps_xy -> strain/2 (engineering gamma = strain), normal stresses 0
cyclic                 uniaxial, eps_xx through -strain x (0.3, 0.05, 0.6, 0.15, 1.0)
=====================  ===============================================

The time step of each step is ``|d eps_control| / rate`` (``rate`` the
magnitude of the controlling strain rate [1/s]).
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from .base import get_model

PATHS = ("uniaxial-compression", "uniaxial-tension", "hydrostatic", "triaxial",
         "shear", "cyclic")
COMPONENTS = ("xx", "yy", "zz", "xy", "yz", "xz")
_PAIRS = ((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2))
DEFAULT_STRAIN = {"uniaxial-compression": 0.01, "uniaxial-tension": 0.002,
                  "hydrostatic": 0.1, "triaxial": 0.02, "shear": 0.01,
                  "cyclic": 0.01}


class _Point:
    """State of one material point (arrays shaped for the group kernel)."""

    def __init__(self, model, params, size):
        self.model = model
        self.params = params
        self.rho = np.array([model.density(params)])
        self.sig = np.zeros((1, 3, 3))
        self.e = np.zeros(1)
        self.c = np.zeros(1)
        self.damage = np.zeros(1)
        self.hist = model.initial_history(params).reshape(1, -1).copy()
        if self.hist.shape[1] == 0:
            self.hist = np.zeros((1, 1))
        self.size = np.array([float(size)])
        self.idx = np.zeros(1, dtype=np.int64)

    def save(self):
        return (self.sig.copy(), self.e.copy(), self.c.copy(), self.damage.copy(),
                self.hist.copy())

    def restore(self, s):
        self.sig[:], self.e[:], self.c[:], self.damage[:], self.hist[:] = s

    def advance(self, deps6, dt):
        """One kernel call with strain increment ``deps6`` over ``dt``."""
        L = np.zeros((1, 3, 3))
        for k, (a, b) in enumerate(_PAIRS):
            L[0, a, b] = deps6[k] / dt
            L[0, b, a] = deps6[k] / dt
        self.model.update(self.idx, L, dt, self.rho, self.sig, self.e, self.c,
                          self.damage, self.hist, self.params, self.size)

    def stress6(self):
        return np.array([self.sig[0, a, b] for a, b in _PAIRS])


def _mixed_step(pt, deps6, groups, target, dt, guess, tol):
    """Advance one step; stress-controlled components reach ``target``.

    ``groups[k] = 0``: component ``k`` strain controlled (increment
    ``deps6[k]``); ``groups[k] = g > 0``: stress controlled, and all
    components of group ``g`` share one unknown strain increment (used for
    the two lateral components of axisymmetric paths: at the triaxial
    meridians the response of a three-invariant model is not differentiable
    with respect to a *single* lateral strain, so the symmetric pair is
    solved as one unknown; exact for isotropic materials). Newton with a
    forward-difference Jacobian and backtracking on the largest residual.
    Returns the strain increment used.
    """
    groups = np.asarray(groups)
    ids = [g for g in sorted(set(groups.tolist())) if g > 0]
    deps = np.array(deps6, dtype=float)
    if not ids:
        pt.advance(deps, dt)
        return deps
    members = [np.flatnonzero(groups == g) for g in ids]
    start = pt.save()
    x = np.array([np.asarray(guess, dtype=float)[m].mean() for m in members])
    scale = max(np.max(np.abs(deps)), np.max(np.abs(x)), 1e-9)

    def residual(xv):
        for m, v in zip(members, xv):
            deps[m] = v
        pt.restore(start)
        pt.advance(deps, dt)
        s6 = pt.stress6()
        return np.array([(s6[m] - target[m]).mean() for m in members])

    r = residual(x)
    for _ in range(40):
        if np.max(np.abs(r)) <= tol:
            return deps.copy()
        J = np.empty((x.size, x.size))
        h = 1e-5 * scale
        for j in range(x.size):
            xh = x.copy()
            xh[j] += h
            J[:, j] = (residual(xh) - r) / h
        try:
            dx = np.linalg.solve(J, -r)
        except np.linalg.LinAlgError:
            dx = np.zeros_like(x)
        if not np.all(np.isfinite(dx)):
            dx = np.zeros_like(x)
        lim = 10.0 * scale
        big = np.max(np.abs(dx))
        if big > lim:
            dx *= lim / big
        # backtracking: accept the first step that lowers the residual
        step, accepted = 1.0, False
        norm0 = np.max(np.abs(r))
        while step > 1e-4:
            r_new = residual(x + step * dx)
            if np.max(np.abs(r_new)) < norm0:
                x, r, accepted = x + step * dx, r_new, True
                break
            step *= 0.5
        if not accepted:
            break
    r = residual(x)
    return deps.copy()


def _segments(path, strain, confinement, n_steps):
    """List of (n, deps6 per step, stress_ctrl mask, stress target start, end)."""
    z = np.zeros(6)
    ctrl_uni = np.array([0, 1, 1, 0, 0, 0])
    if path == "uniaxial-compression":
        return [(n_steps, np.array([-strain / n_steps, 0, 0, 0, 0, 0]), ctrl_uni, z, z)]
    if path == "uniaxial-tension":
        return [(n_steps, np.array([strain / n_steps, 0, 0, 0, 0, 0]), ctrl_uni, z, z)]
    if path == "hydrostatic":
        d = -strain / 3.0 / n_steps
        return [(n_steps, np.array([d, d, d, 0, 0, 0]), np.zeros(6, int), z, z)]
    if path == "shear":
        return [(n_steps, np.array([0, 0, 0, 0.5 * strain / n_steps, 0, 0]),
                 np.array([1, 2, 3, 0, 0, 0]), z, z)]
    if path == "triaxial":
        n1 = max(n_steps // 4, 1)
        conf = np.array([-confinement] * 3 + [0.0] * 3)
        return [(n1, z.copy(), np.array([1, 1, 1, 0, 0, 0]), z, conf),
                (n_steps, np.array([-strain / n_steps, 0, 0, 0, 0, 0]), ctrl_uni,
                 conf, conf)]
    if path == "cyclic":
        marks = [0.0, -0.3, -0.05, -0.6, -0.15, -1.0]
        total = sum(abs(b - a) for a, b in zip(marks, marks[1:]))
        segs = []
        for a, b in zip(marks, marks[1:]):
            n = max(int(round(n_steps * abs(b - a) / total)), 1)
            segs.append((n, np.array([(b - a) * strain / n, 0, 0, 0, 0, 0]),
                         ctrl_uni, z, z))
        return segs
    raise ValueError(f"unknown path {path!r}; choose one of {', '.join(PATHS)}")


def drive(model_name: str, params: dict, path: str, *, strain: float | None = None,
          rate: float = 1e-5, n_steps: int = 400, confinement: float = 0.0,
          size: float = 0.01, out: str | Path | None = None,
          tol: float | None = None) -> dict:
    """Drive one material point of a registered model along a load path.

    Parameters
    ----------
    model_name : str
        Registered model (``"elastic"``, ``"j2"``, ``"cscm"``, ...).
    params : dict
        Material values in SI units as for ``MaterialModel.pack``.
    path : str
        One of :data:`PATHS` (see the module docstring).
    strain : float, optional
        Magnitude of the controlling strain [-] (default per path,
        :data:`DEFAULT_STRAIN`).
    rate : float
        Magnitude of the controlling strain rate [1/s]; ``dt = |d eps|/rate``.
        For the stress-controlled confinement ramp of ``triaxial``
        ``dt`` is that of the following compression steps.
    n_steps : int
        Steps of the main segment (the cyclic path distributes them).
    confinement : float
        Confining pressure of ``triaxial`` [Pa], >= 0.
    size : float
        Particle size passed to the kernel [m] (fracture-energy scale).
    out : path, optional
        Directory for ``<model>_<path>.csv`` and ``.png`` (atomic writes).
    tol : float, optional
        Stress tolerance of the mixed control [Pa] (default ``1e-9 K``).

    Returns
    -------
    dict
        ``t`` (n+1,) [s]; ``strain``, ``stress`` (n+1, 6) [-, Pa] in the
        order ``xx, yy, zz, xy, yz, xz`` (tensor shear); ``damage`` (n+1,);
        ``history`` (n+1, nh) and ``history_names``; ``x``, ``y`` the
        plotted strain and stress (for hydrostatic: volumetric strain and
        pressure, compression positive; for shear: engineering gamma) and
        ``labels`` their names (for plots); ``columns`` the components
        (``"xx"``, ``"xy"``) of the CSV's strain and stress columns that
        control the path (signed, tension positive); ``params``,
        ``bulk_modulus``, ``shear_modulus``, ``rate``, ``confinement`` (for
        the title); ``files``.
    """
    if path not in PATHS:
        raise ValueError(f"unknown path {path!r}; choose one of {', '.join(PATHS)}")
    if not rate > 0.0:
        raise ValueError(f"rate must be > 0, got {rate}")
    if not confinement >= 0.0:
        raise ValueError(f"confinement must be >= 0 (a compressive pressure), got "
                         f"{confinement}")
    model = get_model(model_name)
    p = model.pack(dict(params))
    pt = _Point(model, p, size)
    strain = DEFAULT_STRAIN[path] if strain is None else float(strain)
    tol = 1e-9 * model.bulk_modulus(p) if tol is None else tol
    segs = _segments(path, strain, confinement, int(n_steps))
    dt_main = abs(strain) / int(n_steps) / rate
    eps = np.zeros(6)
    rows_t, rows_e, rows_s, rows_d, rows_h = [0.0], [eps.copy()], [pt.stress6()], \
        [0.0], [pt.hist[0].copy()]
    t = 0.0
    K, G = model.bulk_modulus(p), model.shear_modulus(p)
    nu = (3 * K - 2 * G) / (2 * (3 * K + G))
    guess = np.zeros(6)
    for n, d6, ctrl, s0, s1 in segs:
        for k in range(n):
            target = s0 + (s1 - s0) * (k + 1) / n
            sc = ctrl > 0
            if not guess[sc].any():  # elastic first guess
                if d6[:3].any():
                    guess = np.where(sc, -nu * d6[0], 0.0)
                else:
                    ds = target - pt.stress6()
                    guess = np.zeros(6)
                    guess[:3] = np.where(sc[:3], (ds[:3] - nu * (ds[:3].sum() - ds[:3]))
                                         / (2 * G * (1 + nu)), 0.0)
            dt = dt_main
            used = _mixed_step(pt, d6, ctrl, target, dt, guess, tol)
            guess = np.where(ctrl > 0, used, 0.0)
            eps = eps + used
            t += dt
            rows_t.append(t)
            rows_e.append(eps.copy())
            rows_s.append(pt.stress6())
            rows_d.append(float(pt.damage[0]))
            rows_h.append(pt.hist[0].copy())
        guess = np.zeros(6)
    res = {
        "t": np.array(rows_t), "strain": np.array(rows_e), "stress": np.array(rows_s),
        "damage": np.array(rows_d), "history": np.array(rows_h),
        "history_names": list(model.history_names), "model": model_name, "path": path,
        "params": dict(params), "bulk_modulus": K, "shear_modulus": G, "rate": rate,
        "confinement": confinement,
    }
    comp = 3 if path == "shear" else 0
    res["columns"] = (COMPONENTS[comp], COMPONENTS[comp])  # CSV strain, stress columns
    if path == "hydrostatic":
        res["x"] = -res["strain"][:, :3].sum(axis=1)
        res["y"] = -res["stress"][:, :3].mean(axis=1)
        res["labels"] = ("volumetric strain (compression +)", "pressure [MPa]")
    else:
        res["x"] = res["strain"][:, comp] * (2.0 if comp == 3 else 1.0)
        res["y"] = res["stress"][:, comp]
        res["labels"] = ("shear strain gamma_xy" if comp == 3 else "strain eps_xx",
                         ("shear stress sigma_xy" if comp == 3 else "stress sigma_xx")
                         + " [MPa]")
    res["files"] = write_outputs(res, out) if out is not None else []
    return res


def write_outputs(res: dict, out) -> list[Path]:
    """Write ``<model>_<path>.csv`` (SI; history columns prefixed ``hist_``)
    and ``.png`` into ``out``, each atomically (:mod:`sphdyn.io.atomic`)."""
    from ..io.atomic import atomic_path
    from ..io.plots import save_figure

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    stem = f"{res['model']}_{res['path']}"
    csv_path = out / f"{stem}.csv"
    header = (["t_s"] + [f"strain_{c}" for c in COMPONENTS]
              + [f"stress_{c}_Pa" for c in COMPONENTS] + ["damage"]
              + [f"hist_{n}" for n in res["history_names"]])
    with atomic_path(csv_path) as tmp:
        with open(tmp, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(header)
            nh = len(res["history_names"])
            for k in range(len(res["t"])):
                w.writerow([repr(float(v)) for v in
                            [res["t"][k], *res["strain"][k], *res["stress"][k],
                             res["damage"][k], *res["history"][k][:nh]]])
    png = save_figure(result_figure(res), out / f"{stem}.png", 110)
    return [csv_path, png]


def _number(value) -> str:
    return f"{value:.4g}" if isinstance(value, float) else str(value)


def result_title(res: dict, max_params: int = 6) -> str:
    """Title of a material-point figure: the model, the path and its rate
    (and confinement), the elastic moduli, and the material values given
    (``res["params"]``, SI, at most ``max_params``, then how many more)."""
    head = f"{res['model']}: {res['path']}, rate {res['rate']:g} /s"
    if res['path'] == "triaxial":
        head += f", confinement {res['confinement'] * 1e-6:.4g} MPa"
    moduli = (f"K = {res['bulk_modulus'] * 1e-9:.4g} GPa, "
              f"G = {res['shear_modulus'] * 1e-9:.4g} GPa")
    given = [f"{k} = {_number(v)}" for k, v in res.get("params", {}).items()
             if isinstance(v, (int, float, bool))]
    if len(given) > max_params:
        given = given[:max_params] + [f"(+{len(given) - max_params} more)"]
    return "\n".join([head, ", ".join([moduli] + given[:3])]
                     + ([", ".join(given[3:])] if given[3:] else []))


def result_figure(res: dict):
    """Figure (unsaved) of a :func:`drive` result: stress and damage against
    the controlling strain, shown in per mille, titled by :func:`result_title`."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.ticker import MaxNLocator

    fig = Figure(figsize=(10, 4.6), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.subplots(1, 2)
    strain_label = f"{res['labels'][0]} [‰]"
    x = res["x"] * 1e3
    ax[0].plot(x, res["y"] / 1e6, "k-")   # display in MPa only
    ax[0].set_ylabel(res["labels"][1])
    ax[1].plot(x, res["damage"], "r-")
    ax[1].set_ylabel("damage [-]")
    ax[1].set_ylim(-0.02, 1.02)
    for a in ax:
        a.set_xlabel(strain_label)
        a.xaxis.set_major_locator(MaxNLocator(nbins=6))
        a.grid(True, alpha=0.3)
    fig.suptitle(result_title(res), fontsize=10)
    return fig
