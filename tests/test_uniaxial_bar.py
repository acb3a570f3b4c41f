"""The uniaxial bar stress of sublayer particles (``stiffness = "axial"``,
:mod:`sphdyn.materials.uniaxial`) and the bar directions it reads.

Pinned, with tolerances:

* elastic: along a bar of any direction t the stress is E eps t t^T, whatever
  rates across the bar and shear the particle sees (1e-12 of the stress);
  rates with no part along the bar give no stress at all (exactly);
* J2: tension past yield and back: the stress is the one-dimensional
  elastic-plastic answer sigma_y + E H/(E + H) (eps - sigma_y/E) on loading
  and unloads with E (1e-9 relative: the return is exact for linear
  hardening; round-off only); the same path through the truss element
  (its 3D J2 point held in uniaxial stress by the lateral iterations) gives
  the same axial stress (1e-6 of the yield stress: the truss's lateral
  tolerance);
* energy: the specific energy equals the trapezoidal integral of s d eps / rho
  (1e-12 relative); wave speed sqrt(E / rho) (1e-12);
* directions: a straight bar gives its axis, a bend the bisector of its two
  elements' unit vectors, and flipping elements' node order changes nothing
  (1e-15).
"""

from __future__ import annotations

import numpy as np
import pytest

from sphdyn.interactions.sublayer import bar_directions
from sphdyn.materials import get_model
from sphdyn.materials.uniaxial import H_DIRECTION, H_PLASTIC, H_STRESS, UNIAXIAL, \
    uniaxial_params
from sphdyn.parts.fem.gather import node_element_list

E, NU, RHO = 200e9, 0.3, 2400.0
SY, H = 500e6, 2e9


def _params(model="j2"):
    values = {"density": 7850.0, "E": E, "nu": NU, "yield_stress": SY,
              "hardening_modulus": H}
    if model == "elastic":
        values = {k: values[k] for k in ("density", "E", "nu")}
    return uniaxial_params(model, get_model(model).pack(values))


def _drive(params, t, rates, dt=1e-6, extra=None):
    """One particle along direction t through the axial ``rates`` [1/s]
    (one per step), with ``extra`` (3, 3) added to L every step; the stress
    tensors, axial stresses and energies after each step."""
    n = 1
    sig, hist = np.zeros((n, 3, 3)), np.zeros((n, UNIAXIAL.n_history))
    hist[0, H_DIRECTION:H_DIRECTION + 3] = t
    rho, e, c, dmg = np.full(n, RHO), np.zeros(n), np.zeros(n), np.zeros(n)
    out = []
    for r in rates:
        L = np.zeros((n, 3, 3))
        L[0] = r * np.outer(t, t) + (0.0 if extra is None else extra)
        UNIAXIAL.update(np.zeros(1, np.int64), L, dt, rho, sig, e, c, dmg, hist, params,
                        np.full(n, 0.01))
        out.append((sig[0].copy(), hist[0, H_STRESS], e[0], c[0], hist[0, H_PLASTIC]))
    return out


def test_elastic_bar_stress_acts_along_the_bar_only():
    t = np.array([1.0, 2.0, -2.0]) / 3.0
    n1 = np.array([2.0, 1.0, 2.0]) / 3.0  # across the bar (t . n1 = 0)
    across = 3e3 * np.outer(n1, n1) + 5e3 * (np.outer(t, n1) + np.outer(n1, t)) \
        + 2e3 * (np.outer(t, n1) - np.outer(n1, t))  # lateral, shear and spin rates
    rate, dt, steps = 1e3, 1e-6, 5
    path = _drive(_params("elastic"), t, [rate] * steps, dt, across)
    sig, s, e, c, _ = path[-1]
    eps = rate * dt * steps
    assert s == pytest.approx(E * eps, rel=1e-12)
    assert np.abs(sig - E * eps * np.outer(t, t)).max() < 1e-12 * E * eps
    assert c == pytest.approx(np.sqrt(E / RHO), rel=1e-12)
    # the energy: trapezoid of s d eps / rho, exact for linear elasticity
    assert e == pytest.approx(0.5 * E * eps ** 2 / RHO, rel=1e-12)
    # nothing along the bar, no stress
    none = _drive(_params("elastic"), t, [0.0] * 3, dt, across)
    assert np.all(none[-1][0] == 0.0) and none[-1][2] == 0.0


def test_j2_bar_follows_the_one_dimensional_elastic_plastic_law():
    t = np.array([0.0, 0.6, 0.8])
    dt, rate = 1e-6, 1e2  # 1e-4 per step: yield (2.5e-3) in 25 steps
    rates = [rate] * 100 + [-rate] * 30
    path = _drive(_params(), t, rates, dt)
    eps = np.cumsum(np.array(rates) * dt)
    s = np.array([p[1] for p in path])
    ey = SY / E
    load = s[:100]
    expect = np.where(eps[:100] <= ey, E * eps[:100],
                      SY + E * H / (E + H) * (eps[:100] - ey))
    assert np.abs(load - expect).max() < 1e-9 * SY
    top = s[99]
    assert np.abs(s[100:] - (top - E * (eps[99] - eps[100:]))).max() < 1e-9 * SY
    assert path[-1][4] == pytest.approx((top - SY) / H, rel=1e-9)  # plastic strain
    # energy: the trapezoid of the axial stress over the axial strain
    s_prev = np.concatenate([[0.0], s[:-1]])
    work = np.sum(0.5 * (s_prev + s) * np.array(rates) * dt) / RHO
    assert path[-1][2] == pytest.approx(work, rel=1e-12)


def test_the_bar_particles_and_the_truss_share_one_law():
    """A J2 truss element stretched past yield (its 3D point held in uniaxial
    stress by the lateral iterations) and a uniaxial particle on the same axial
    strain path carry the same axial stress."""
    from sphdyn.parts.fem.line_part import BeamSection, LinePart

    values = {"density": 7850.0, "E": E, "nu": NU, "yield_stress": SY,
              "hardening_modulus": H}
    bar = LinePart("b", np.array([[0.0, 0, 0], [0.1, 0, 0]]), np.array([[0, 1]]),
                   element="truss", section=BeamSection.circle(0.01),
                   material=("j2", values))
    dt, rate, steps = 1e-7, 1e3, 60  # 1e-4 per step, 6e-3 in all
    truss, lengths = [], [0.1]
    for _ in range(steps):
        bar.kin.v[1, 0] = rate * (bar.kin.x[1, 0] - bar.kin.x[0, 0])
        bar.drift(dt)
        bar.update_geometry(0.0, dt)
        bar.internal_forces(0.0, dt)
        truss.append(bar.points.sig[0, 0, 0])
        lengths.append(bar.kin.x[1, 0] - bar.kin.x[0, 0])
    # the particle sees the truss's logarithmic rate ln(l_n+1 / l_n) / dt
    rates = np.log(np.array(lengths[1:]) / np.array(lengths[:-1])) / dt
    path = _drive(_params(), np.array([1.0, 0.0, 0.0]), rates, dt)
    s = np.array([p[1] for p in path])
    assert s[-1] > 1.01 * SY  # past yield, hardening
    assert np.abs(s - np.array(truss)).max() < 1e-6 * SY


@pytest.mark.parametrize("flip", [(), (1,), (0, 2)])
def test_bar_directions_straight_and_bent(flip):
    """Elements 0-1 along x, element 2 turned by 120 degrees from it (a 60
    degree bend); ``flip`` reverses some elements' node order."""
    x = np.array([[0.0, 0, 0], [1.0, 0, 0], [2.0, 0, 0], [2.5, np.sqrt(0.75), 0]])
    conn = np.array([[0, 1], [1, 2], [2, 3]], dtype=np.int64)
    conn[list(flip)] = conn[list(flip), ::-1]
    offsets, slots = node_element_list(conn, 4)
    nodes = np.arange(4, dtype=np.int64)
    rows = nodes + 10
    hist = np.zeros((14, 7))
    bar_directions(x, conn, offsets, slots, nodes, rows, hist, 2)
    t = hist[rows, 2:5]
    axis = np.array([1.0, 0.0, 0.0])
    bisector = np.array([1.5, np.sqrt(0.75), 0.0]) / np.sqrt(3.0)  # (u1 + u2)/|u1 + u2|
    last = np.array([0.5, np.sqrt(0.75), 0.0])
    for k, want in enumerate([axis, axis, bisector, last]):
        assert min(np.abs(t[k] - want).max(), np.abs(t[k] + want).max()) < 1e-15, k
    assert np.all(hist[:10] == 0.0) and np.all(hist[rows][:, [0, 1, 5, 6]] == 0.0)
