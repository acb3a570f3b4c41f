"""Run guards: non-finite values, particles leaving the domain, time-step collapse,
energy made from nothing.

A failed check raises :class:`SimulationFailed` with a diagnosis naming the
particles, where they are and which quantity went wrong; the runner then
writes everything it has and exits non-zero.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

OK = 0
NONFINITE = 1
OUTSIDE = 2


class SimulationFailed(RuntimeError):
    """The run stopped on a guard; ``diagnosis`` is a human-readable report,
    ``status`` the summary's status."""

    status = "failed"

    def __init__(self, diagnosis: str):
        super().__init__(diagnosis)
        self.diagnosis = diagnosis


class EnergyError(SimulationFailed):
    """The energy balance broke its limit (:func:`energy_diagnosis`)."""

    status = "energy_error"


def energy_diagnosis(s, error: float, limit: float, scale: float, growth: float) -> str:
    r"""What made the energy of stepper ``s``: a report for the energy guard.

    ``error`` the relative energy error (``growth`` [J] over ``scale`` [J],
    the largest energy term so far) past ``limit``. Each part's residual is
    its gain beyond the work done on it since the first kick,
    :math:`R_p = \Delta(E_{kin,p} + E_{int,p}) - W_p` (``W_p`` the work of the
    interaction accelerations and boundary reactions on its items, the
    stepper's ``part_work``; minus its released chemical energy); the part
    of the largest :math:`R_p` is named, with
    what its ``hotspot()`` says (the element or particle of the largest
    specific internal energy, the fastest item) and the interactions acting
    on it, with their own work when ``[output] interaction_work`` books it.
    """
    lines = [f"run stopped at t = {s.t:.6e} s, step {s.step_count}: the energy balance "
             f"is off by {growth:+.4g} J, {100 * error:.3g} % of the largest energy "
             f"term ({scale:.4g} J), past energy_error_limit = {limit:g}."]
    rows = []
    for part in s.parts:
        now = s.part_kinetic[part.name] + part.energies()[0]
        gain = now - s.part_start.get(part.name, now)
        made = gain - s.part_work[part.name]
        made -= getattr(part, "energy_released", None) or 0.0
        rows.append((made, gain, part))
    made, gain, part = max(rows, key=lambda r: r[0])
    lines.append(f"  Part '{part.name}' gained the most beyond "
                 f"the work done on it: {made:+.4g} J (its kinetic + internal energy "
                 f"{gain:+.4g} J, work on it {s.part_work[part.name]:+.4g} J).")
    others = [f"'{p.name}' {m:+.4g} J" for m, _, p in rows if p is not part]
    if others:
        lines.append("  The other parts: " + ", ".join(others) + ".")
    hotspot = getattr(part, "hotspot", None)
    lines.append("  In it: " + (hotspot() if hotspot is not None else fastest(part.kin))
                 + ".")
    acting = [i for i in s.interactions  # on the part, or coupling it to another
              if any(v is part for v in vars(i).values())]
    if acting:
        books = s.books.work if s.books is not None else {}
        named = [f"'{i.name}'" + (f" (work {books[i.name]:+.4g} J)" if i.name in books
                                  else "") for i in acting]
        lines.append("  Interactions acting on it: " + ", ".join(named) + "."
                     + ("" if s.books is not None else
                        " ([output] interaction_work = true books each one's work.)"))
    if s.events:
        lines.append("  Events (" + ", ".join(e.name for e in s.events) + ") move energy "
                     "between parts; the residuals include what they moved.")
    lines.append("  Likely causes: an element or particle crushed or inverted (see its "
                 "specific energy), a time step too large for a contact or material "
                 "(lower sph.cfl or the contact's alpha), an interaction changing "
                 "velocities outside the work books, or a model error in the named "
                 "part. Raise [run] energy_error_limit or set energy_error_action = "
                 "\"warn\" only if the error is understood.")
    return "\n".join(lines)


#: stand-ins for the stress and density of items that have none (mesh nodes)
_NO_SIG = np.zeros((0, 3, 3))
_NO_RHO = np.zeros(0)


@njit(cache=True, error_model="numpy")
def outside_box(x, i, lo, hi):
    """Whether row ``i`` of ``x`` (N, 3) lies outside the box ``[lo, hi]`` (3,)."""
    for d in range(3):
        if x[i, d] < lo[d] or x[i, d] > hi[d]:
            return True
    return False


@njit(cache=True, error_model="numpy", parallel=True)
def _flags(x, v, a, sig, rho, active, lo, hi, out):
    """Flag (N,) items: non-finite x, v, a (and stress, density when ``sig``,
    ``rho`` have N rows; mesh nodes pass empty ones) or outside [lo, hi].
    Items with ``active == 0`` (removed from the calculation) are not checked."""
    n = x.shape[0]
    full = sig.shape[0] == n and rho.shape[0] == n
    bad = 0
    for i in prange(n):
        f = OK
        if active[i] == 0:
            out[i] = f
            continue
        s = a[i, 0] + a[i, 1] + a[i, 2] + v[i, 0] + v[i, 1] + v[i, 2]
        s += x[i, 0] + x[i, 1] + x[i, 2]
        r = 1.0
        if full:
            r = rho[i]
            s += r + sig[i, 0, 0] + sig[i, 1, 1] + sig[i, 2, 2] + sig[i, 0, 1]
            s += sig[i, 0, 2] + sig[i, 1, 2]
        if not np.isfinite(s) or r <= 0.0:
            f = NONFINITE
        elif outside_box(x, i, lo, hi):
            f = OUTSIDE
        out[i] = f
        if f != OK:
            bad += 1
    return bad


def check_particles(p, lo, hi, t, step, work: np.ndarray, label: str = "") -> None:
    """Raise :class:`SimulationFailed` if any particle is non-finite or outside.

    ``work`` is an (N,) int8 scratch array (no allocation per step). Mesh
    nodes (no ``sig``, ``rho``) are checked for their kinematics; ``label``
    (``"node(s) of mesh 'beam'"``) names them in the diagnosis.
    """
    sig, rho = getattr(p, "sig", _NO_SIG), getattr(p, "rho", _NO_RHO)
    if _flags(p.x, p.v, p.a, sig, rho, p.active, lo, hi, work) == 0:
        return
    what = label or "particle(s)"
    lines = [f"run stopped at t = {t:.6e} s, step {step}:"]
    nonfinite = np.flatnonzero(work == NONFINITE)
    outside = np.flatnonzero(work == OUTSIDE)
    if nonfinite.size:
        fields = {"position": p.x, "velocity": p.v, "acceleration": p.a}
        if sig.shape[0] == p.n:
            fields.update(stress=sig.reshape(p.n, 9), density=rho[:, None])
        which = [name for name, arr in fields.items()
                 if not np.all(np.isfinite(arr[nonfinite]))]
        if rho.shape[0] == p.n and np.any(rho[nonfinite] <= 0):
            which.append("density <= 0")
        lines.append(f"  {nonfinite.size} {what} with non-finite values in "
                     f"{', '.join(which) or 'state'}; first: "
                     + _describe(p, nonfinite[:5]))
        lines.append("  Likely causes: time step too large (lower sph.cfl), too "
                     "stiff contact (lower wall.alpha), or a material failing to converge.")
    if outside.size:
        lines.append(f"  {outside.size} {what} left the domain box "
                     f"[{_fmt(lo)} .. {_fmt(hi)}]; first: " + _describe(p, outside[:5]))
        lines.append("  Enlarge [domain] (lo/hi or margin) if this motion is physical.")
    raise SimulationFailed("\n".join(lines))


def check_time_step(dt, dt0, ratio, t, step, k, p, describe=None) -> None:
    """Raise :class:`SimulationFailed` when ``dt < ratio * dt0`` (time-step collapse).

    ``k`` is the controlling item of ``p`` (a particle), or of a part whose
    ``describe(k)`` says what it is (an element of a mesh).
    """
    if dt >= ratio * dt0 and np.isfinite(dt):
        return
    if describe is not None:
        raise SimulationFailed(
            f"run stopped at t = {t:.6e} s, step {step}: time step collapsed to "
            f"{dt:.3e} s (< {ratio:g} x initial {dt0:.3e} s), controlled by "
            f"{describe(k)}.\n  Likely causes: an element being crushed or inverted; "
            "check the loads, contact stiffness and materials, or erode the element.")
    raise SimulationFailed(
        f"run stopped at t = {t:.6e} s, step {step}: time step collapsed to "
        f"{dt:.3e} s (< {ratio:g} x initial {dt0:.3e} s), controlled by particle {k} "
        f"at {_fmt(p.x[k])} with h = {p.h[k]:.3e} m, wave speed {p.c[k]:.3e} m/s, "
        f"speed {np.linalg.norm(p.v[k]):.3e} m/s.\n"
        "  Likely causes: a particle being crushed (h at its minimum) or accelerating "
        "without bound; check materials and contact stiffness.")


def _fmt(v) -> str:
    return "(" + ", ".join(f"{c:.4g}" for c in v) + ")"


def _describe(p, idx) -> str:
    body = getattr(p, "body", None)
    return "; ".join(f"#{i}" + ("" if body is None else f" (body {body[i]})")
                     + f" at {_fmt(p.x[i])}" for i in idx)


def fastest(q, what: str = "item") -> str:
    """The fastest active item of kinematics ``q`` (a diagnosis' phrase)."""
    speed = np.where(q.active != 0, np.sqrt(np.sum(q.v * q.v, axis=1)), 0.0)
    if speed.size == 0:
        return f"no {what}s"
    k = int(np.argmax(speed))
    return f"the fastest {what} #{k} at {_fmt(q.x[k])}, {speed[k]:.4g} m/s"
