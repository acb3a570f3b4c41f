"""Penalty contact between particles of different bodies (sphdyn.interactions.particle_contact)."""

import numpy as np

from sphdyn.interactions.particle_contact import contact_time_step, particle_contact
from sphdyn.integrate import drift, kick, kick_scratch
from sphdyn.neighbours import build_neighbours, update_neighbours


def _pair(gap, dim=2):
    s = 1e-3
    x = np.array([[0.0, 0, 0], [s + gap, 0, 0]])
    m = np.array([1000 * s**dim, 2 * 1000 * s**dim])
    return x, m, np.full(2, s), np.array([1e9, 3e9]), np.array([0, 1], np.int32)


def test_pair_force_is_antisymmetric_and_only_between_bodies():
    x, m, size, kb, body = _pair(-0.1e-3)
    nl = build_neighbours(x, size, 1.0, 0.0, 2)
    a = np.zeros((2, 3))
    n = particle_contact(x, m, size, kb, body, 2, nl.offsets, nl.idx, 0.5, 1.0, a)
    assert n == 2
    assert np.allclose(m[0] * a[0] + m[1] * a[1], 0.0, atol=1e-15 * abs(m[0] * a[0, 0]))
    # spring k = alpha * mean(K) * s^(d-2) = 0.5 * 2e9 * 1 in 2D, penetration 0.1 mm
    assert np.isclose(m[1] * a[1, 0], 0.5 * 2e9 * 0.1e-3)
    assert a[0, 0] < 0 < a[1, 0]  # pushed apart
    a[:] = 0
    body[:] = 0  # same body: no contact
    assert particle_contact(x, m, size, kb, body, 2, nl.offsets, nl.idx, 0.5, 1.0, a) == 0
    assert np.all(a == 0)


def test_head_on_bounce_is_elastic():
    # Two particles approach, touch and separate: the linear spring is
    # conservative, so the relative speed after the bounce equals the one
    # before (leapfrog with dt 1/20 of the contact limit: 1e-3 relative).
    x, m, size, kb, body = _pair(0.2e-3)
    v = np.array([[10.0, 0, 0], [-5.0, 0, 0]])
    dt = 0.05 * contact_time_step(m, size, kb, 2, 0.5, n_contacts=1)
    nl = build_neighbours(x, size, 1.0, 0.5e-3, 2)
    a = np.zeros((2, 3))
    zero = np.zeros((2, 3))
    bc = np.zeros(2, np.int8)
    vm = np.zeros((2, 3))
    p0 = (m[:, None] * v).sum(axis=0)
    for k in range(4000):
        a[:] = 0.0
        nl = update_neighbours(nl, x, size, 2)
        particle_contact(x, m, size, kb, body, 2, nl.offsets, nl.idx, 0.5, 1.0, a)
        kick(v, a, zero, m, bc, zero, 0.5 * dt if k == 0 else dt, vm, kick_scratch(2))
        drift(x, v, dt)
    rel = v[1, 0] - v[0, 0]
    assert abs(rel - 15.0) < 15.0 * 1e-3, rel
    assert np.allclose((m[:, None] * v).sum(axis=0), p0, rtol=1e-12, atol=1e-15)
