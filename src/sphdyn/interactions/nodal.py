"""Prescribed motion, nodal loads and mass damping on a set of a part's items.

These act on the items (mesh nodes or particles) of one part:

* :class:`PrescribedMotion`: fixed items, or a velocity or displacement
  reached over a ramp (LS-DYNA's BOUNDARY_SPC and BOUNDARY_PRESCRIBED_MOTION);
  it reports the reaction force the constraint exerts;
* :class:`NodalLoad`: a total force shared by the items, ramped or scaled by
  a time curve (:class:`TimeFactor`);
* :class:`MassDamping`: :math:`\\mathbf a \\mathrel{-}= c\\,\\mathbf v`
  (mass-proportional damping, LS-DYNA's DAMPING_GLOBAL), the usual way to
  reach a static state with an explicit code (dynamic relaxation).

Ramps (:func:`ramp`) take a value from 0 at t = 0 to 1 at t = T: ``linear``
or ``smooth`` (:math:`s - \\sin(2\\pi s)/2\\pi`, :math:`s = t/T`, whose rate
starts and ends at zero, so a prescribed displacement starts and stops
without a jerk). A time curve (:func:`curve_value`) takes the factor from a
table of ``(t, factor)`` points instead.

The model and its tests: docs/theory.md, "Prescribed motion, loads and damping".
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..state import BC_COMPONENTS, BC_FIXED, BC_VELOCITY
from .base import InteractionBase

RAMPS = ("linear", "smooth")


def ramp(t: float, T: float, shape: str = "linear") -> float:
    """Ramp value in [0, 1] at time ``t`` [s] for ramp time ``T`` [s] (1 if T = 0)."""
    if T <= 0.0 or t >= T:
        return 1.0
    if t <= 0.0:
        return 0.0
    s = t / T
    if shape == "smooth":
        return s - math.sin(2.0 * math.pi * s) / (2.0 * math.pi)
    return s


def curve_value(t: float, times: np.ndarray, factors: np.ndarray) -> float:
    """Factor of a time curve at ``t`` [s]: linear between the points ``times``
    (k,) [s, increasing], ``factors`` (k,); the first or last factor outside them."""
    return float(np.interp(t, times, factors))


class TimeFactor:
    """The factor a load is scaled by at time ``t``: :func:`ramp` (``ramp_time``,
    ``shape``) or, given ``curve`` ((k, 2) ``(t, factor)`` points), :func:`curve_value`."""

    def __init__(self, ramp_time: float = 0.0, shape: str = "linear", curve=None):
        if shape not in RAMPS:
            raise ValueError(f"ramp shape must be one of {RAMPS}")
        self.ramp_time, self.shape = float(ramp_time), shape
        self.curve = None
        if curve is not None:
            c = np.asarray(curve, dtype=float)
            if (c.ndim != 2 or c.shape[1] != 2 or c.shape[0] < 1
                    or np.any(np.diff(c[:, 0]) <= 0.0)):
                raise ValueError("a time curve is (k, 2) (t, factor) points with "
                                 "increasing times")
            self.curve = (np.ascontiguousarray(c[:, 0]), np.ascontiguousarray(c[:, 1]))

    def __call__(self, t: float) -> float:
        if self.curve is None:
            return ramp(t, self.ramp_time, self.shape)
        return curve_value(t, *self.curve)


@njit(cache=True, error_model="numpy")
def reaction(idx, m, v, v_mid, a, dt_kick):
    r"""Force the constraint exerted on the items ``idx`` at the last kick [N]:
    :math:`\sum m ((\mathbf v^{n+1/2} - \mathbf v^{n-1/2})/\Delta t^n -
    \mathbf a^n)` with :math:`\mathbf v^{n-1/2} = 2\mathbf v^n - \mathbf v^{n+1/2}`
    (``v_mid`` holds :math:`\mathbf v^n`); ``m`` (N,), ``v``, ``v_mid``, ``a`` (N, 3)."""
    r0 = 0.0
    r1 = 0.0
    r2 = 0.0
    for i in idx:
        r0 += m[i] * (2.0 * (v[i, 0] - v_mid[i, 0]) / dt_kick - a[i, 0])
        r1 += m[i] * (2.0 * (v[i, 1] - v_mid[i, 1]) / dt_kick - a[i, 1])
        r2 += m[i] * (2.0 * (v[i, 2] - v_mid[i, 2]) / dt_kick - a[i, 2])
    return r0, r1, r2


@njit(cache=True, error_model="numpy")
def add_load(idx, per_mass, scale, force, a_own, a_out):
    """``a_own[k] = scale * per_mass[k] * force`` (k, 3) [m/s^2], added to
    ``a_out[idx[k]]`` (force (3,) [N], per_mass (k,) [1/kg])."""
    for k in range(idx.shape[0]):
        f = scale * per_mass[k]
        i = idx[k]
        for j in range(3):
            a_own[k, j] = f * force[j]
            a_out[i, j] += a_own[k, j]


@njit(cache=True, error_model="numpy")
def damp(idx, v, c, a_own, a_out):
    """``a_own[k] = -c v[idx[k]]`` (k, 3), added to ``a_out`` (N, 3) [m/s^2]."""
    for k in range(idx.shape[0]):
        i = idx[k]
        for j in range(3):
            a_own[k, j] = -c * v[i, j]
            a_out[i, j] += a_own[k, j]


@njit(cache=True, error_model="numpy")
def set_work(idx, m, a_own, v_mid, dt_kick):
    r"""Work of the accelerations ``a_own`` (k, 3) on the items ``idx`` over a kick:
    :math:`\sum m\, \mathbf a \cdot \mathbf v^n\, \Delta t^n` [J]."""
    w = 0.0
    for k in range(idx.shape[0]):
        i = idx[k]
        w += m[i] * (a_own[k, 0] * v_mid[i, 0] + a_own[k, 1] * v_mid[i, 1]
                     + a_own[k, 2] * v_mid[i, 2])
    return w * dt_kick


class _SetInteraction(InteractionBase):
    """An interaction on the items ``idx`` of one part."""

    def __init__(self, name: str, part, idx: np.ndarray):
        idx = np.asarray(idx, dtype=np.int64)
        if idx.size == 0:
            raise ValueError(f"{name}: the set is empty. Fix: make its [[set]] region "
                             "(or its nodes) select at least one particle or node of "
                             "the body or mesh it names")
        self.name = name
        self.part = part
        self.idx = idx


class PrescribedMotion(_SetInteraction):
    """Fixed items, or a prescribed velocity or displacement with a ramp.

    Parameters
    ----------
    kind : ``"fixed"``, ``"velocity"`` (the velocity ``value`` [m/s] reached
        over the ramp) or ``"displacement"`` (the displacement ``value`` [m]
        reached over the ramp, then held).
    value : (3,) vector.
    ramp_time : T [s]; ``shape``: ``linear`` or ``smooth``.
    components : the axes (0, 1, 2) the condition holds (default all); the
        others stay free (a roller support holds only the normal). Conditions
        on different components of the same items combine.

    Each step [t, t + dt] the items get the velocity that moves them exactly
    along the displacement history: :math:`(d(t + \\Delta t) - d(t))/\\Delta t`
    (the stepper calls :meth:`prescribe` with the step's own dt).

    The reaction (column ``<name>_reaction_x|y|z``, N or N/m in 2D) is the
    force the constraint exerts on the items at the kick:
    :math:`\\sum m ((\\mathbf v^{n+1/2} - \\mathbf v^{n-1/2})/\\Delta t^n - \\mathbf a^n)`.
    """

    def __init__(self, name: str, part, idx, kind: str = "fixed", value=(0.0, 0.0, 0.0),
                 ramp_time: float = 0.0, shape: str = "linear", components=(0, 1, 2)):
        super().__init__(name, part, idx)
        if kind not in ("fixed", "velocity", "displacement"):
            raise ValueError(f"{name}: kind must be fixed, velocity or displacement")
        if shape not in RAMPS:
            raise ValueError(f"{name}: ramp shape must be one of {RAMPS}")
        self.comps = np.unique(np.asarray(components, dtype=np.int64))
        if self.comps.size == 0 or self.comps[0] < 0 or self.comps[-1] > 2:
            raise ValueError(f"{name}: components must be axes 0, 1, 2, got {components!r}")
        self.kind, self.shape = kind, shape
        self.value = np.asarray(value, dtype=float)
        self.ramp_time = float(ramp_time)
        q = part.kin
        if self.comps.size == 3:
            q.bc[self.idx] = BC_FIXED if kind == "fixed" else BC_VELOCITY
        else:
            mask = int(np.sum(1 << self.comps))
            old = q.bc[self.idx].astype(np.int64)
            # earlier conditions on the same items combine with this one
            held = np.where(old >= BC_COMPONENTS, old - BC_COMPONENTS,
                            np.where((old == BC_FIXED) | (old == BC_VELOCITY), 7, 0))
            mask = held | mask
            q.bc[self.idx] = np.where(mask == 7, BC_VELOCITY, BC_COMPONENTS + mask)
        self._set(q.v, self.velocity(0.0, 0.0))
        self._set(q.bc_v, self.velocity(0.0, 0.0))
        self.reaction = np.zeros(3)

    def _set(self, target: np.ndarray, value: np.ndarray) -> None:
        """``target[idx, comps] = value[comps]`` (the held components only)."""
        for c in self.comps:
            target[self.idx, c] = value[c]

    def displacement(self, t: float) -> np.ndarray:
        """Prescribed displacement at ``t`` [m] (``displacement`` kind)."""
        return self.value * ramp(t, self.ramp_time, self.shape)

    def velocity(self, t: float, dt: float) -> np.ndarray:
        """Velocity over the step [t, t + dt] [m/s]."""
        if self.kind == "fixed":
            return np.zeros(3)
        if self.kind == "velocity":
            return self.value * ramp(t + 0.5 * dt, self.ramp_time, self.shape)
        if dt <= 0.0:
            return np.zeros(3)
        return (self.displacement(t + dt) - self.displacement(t)) / dt

    def prescribe(self, t: float, dt: float) -> None:
        if self.kind != "fixed":
            self._set(self.part.kin.bc_v, self.velocity(t, dt))

    def forces(self, t: float, dt: float, a_out: np.ndarray) -> None:
        return None

    def after_kick(self, dt_kick: float) -> None:
        q = self.part.kin
        if dt_kick > 0.0:
            self.reaction[:] = reaction(self.idx, q.inertia(), q.v, q.v_mid, q.a, dt_kick)

    def columns(self, t: float) -> dict[str, float]:
        r = self.reaction
        return {f"{self.name}_reaction_x": float(r[0]), f"{self.name}_reaction_y": float(r[1]),
                f"{self.name}_reaction_z": float(r[2])}

    def summary(self, history: dict, window: float) -> dict:
        """``peak_<name>_reaction``: the largest magnitude of the reaction [N]
        (N/m in 2D) over the history."""
        cols = [history.get(f"{self.name}_reaction_{c}", np.zeros(0)) for c in "xyz"]
        if not cols[0].size:
            return {}
        return {f"peak_{self.name}_reaction": float(np.max(np.linalg.norm(cols, axis=0)))}


class NodalLoad(_SetInteraction):
    """A total force ``force`` (3,) [N] shared evenly by the items, times a ramp
    (``ramp_time``, ``shape``) or a time curve (``curve``, :class:`TimeFactor`).

    Columns ``<name>_force``: the magnitude applied now [N]; ``W_<name>``:
    its work so far [J] (J/m in 2D), :math:`\\sum_n \\sum_k m_k \\mathbf a_k
    \\cdot \\mathbf v_k^n \\Delta t^n` at the kicks (:func:`set_work`), booked
    as external work (``W_external``), as gravity's.
    """

    external = True  # its work is external work (W_external)

    def __init__(self, name: str, part, idx, force, ramp_time: float = 0.0,
                 shape: str = "linear", curve=None):
        super().__init__(name, part, idx)
        self.force = np.asarray(force, dtype=float)
        self.factor = TimeFactor(ramp_time, shape, curve)
        m = part.kin.m[self.idx]
        if np.any(m <= 0.0):
            raise ValueError(f"{name}: a load on items without mass")
        self._per_mass = 1.0 / (self.idx.size * m)
        self._now = 0.0
        self._a = np.zeros((self.idx.size, 3))  # the load's accelerations [m/s^2]
        self.work = 0.0  # total [J]
        self._kick = 0.0  # over the last kick [J]

    def forces(self, t: float, dt: float, a_out: np.ndarray) -> None:
        self._now = self.factor(t)
        add_load(self.idx, self._per_mass, self._now, self.force, self._a, a_out)

    def after_kick(self, dt_kick: float) -> None:
        q = self.part.kin
        self._kick = set_work(self.idx, q.m, self._a, q.v_mid, dt_kick)
        self.work += self._kick

    def external_work(self) -> float:
        return self._kick

    def columns(self, t: float) -> dict[str, float]:
        return {f"{self.name}_force": float(self._now * np.linalg.norm(self.force)),
                f"W_{self.name}": self.work}

    def state(self) -> tuple[dict, dict[str, np.ndarray]]:
        return {"now": self._now, "work": self.work, "kick": self._kick}, {"a": self._a}

    def restore(self, scalars: dict, arrays: dict) -> None:
        self._now = float(scalars["now"])
        self.work = float(scalars["work"])
        self._kick = float(scalars["kick"])
        self._a[...] = arrays["a"]


class MassDamping(_SetInteraction):
    """Mass-proportional damping :math:`\\mathbf a \\mathrel{-}= c\\,\\mathbf v` [c in 1/s].

    Critical damping of a mode of angular frequency :math:`\\omega` is
    :math:`c = 2\\omega`: the fastest approach to a static state in that mode
    (Underwood 1983, dynamic relaxation). The velocity used is the latest
    (:math:`n + 1/2`). Column ``E_damping_<name>``: the energy it removed [J].
    """

    def __init__(self, name: str, part, idx, coefficient: float):
        super().__init__(name, part, idx)
        if coefficient < 0.0:
            raise ValueError(f"{name}: the damping coefficient must be >= 0")
        self.c = float(coefficient)
        self._a = np.zeros((self.idx.size, 3))
        self.removed = 0.0

    def forces(self, t: float, dt: float, a_out: np.ndarray) -> None:
        damp(self.idx, self.part.kin.v, self.c, self._a, a_out)

    def after_kick(self, dt_kick: float) -> None:
        q = self.part.kin
        self.removed -= set_work(self.idx, q.m, self._a, q.v_mid, dt_kick)

    def columns(self, t: float) -> dict[str, float]:
        return {f"E_damping_{self.name}": self.removed}

    def state(self) -> tuple[dict, dict[str, np.ndarray]]:
        return {"removed": self.removed}, {"a": self._a}

    def restore(self, scalars: dict, arrays: dict) -> None:
        self.removed = float(scalars["removed"])
        self._a[...] = arrays["a"]
