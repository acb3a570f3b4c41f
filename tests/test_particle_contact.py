"""Penalty contact between particles of different bodies (sphdyn.interactions.particle_contact)."""

import numpy as np

from sphdyn.interactions.particle_contact import contact_time_step, particle_contact
from sphdyn.integrate import drift, kick, kick_scratch
from sphdyn.neighbours import build_neighbours, update_neighbours


NO = np.zeros(2)  # no overlap allowance
TL = np.array([True, False])  # one total-Lagrangian particle: contact applies
over = np.zeros(2)  # scratch: the deepest raw overlap


def _pair(gap, dim=2):
    s = 1e-3
    x = np.array([[0.0, 0, 0], [s + gap, 0, 0]])
    m = np.array([1000 * s**dim, 2 * 1000 * s**dim])
    return x, m, np.full(2, s), np.array([1e9, 3e9]), np.array([0, 1], np.int32)


def test_pair_force_is_antisymmetric_and_only_between_bodies():
    x, m, size, kb, body = _pair(-0.1e-3)
    nl = build_neighbours(x, size, 1.0, 0.0, 2)
    a = np.zeros((2, 3))
    n = particle_contact(x, m, size, kb, body, TL, 2, nl.offsets, nl.idx, 0.5, 1.0, NO,
                         over, a)
    assert n == 2
    assert np.allclose(m[0] * a[0] + m[1] * a[1], 0.0, atol=1e-15 * abs(m[0] * a[0, 0]))
    # spring k = alpha * mean(K) * s^(d-2) = 0.5 * 2e9 * 1 in 2D, penetration 0.1 mm
    assert np.isclose(m[1] * a[1, 0], 0.5 * 2e9 * 0.1e-3)
    assert a[0, 0] < 0 < a[1, 0]  # pushed apart
    a[:] = 0
    # two updated-Lagrangian particles meet through the kernel: no contact
    assert particle_contact(x, m, size, kb, body, np.zeros(2, bool), 2, nl.offsets,
                            nl.idx, 0.5, 1.0, NO, over, a) == 0
    assert np.all(a == 0)
    body[:] = 0  # same body: no contact
    assert particle_contact(x, m, size, kb, body, TL, 2, nl.offsets, nl.idx, 0.5, 1.0, NO,
                         over, a) == 0
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
        particle_contact(x, m, size, kb, body, TL, 2, nl.offsets, nl.idx, 0.5, 1.0, NO,
                         over, a)
        kick(v, a, zero, m, bc, zero, 0.5 * dt if k == 0 else dt, vm, kick_scratch(2))
        drift(x, v, dt)
    rel = v[1, 0] - v[0, 0]
    assert abs(rel - 15.0) < 15.0 * 1e-3, rel
    assert np.allclose((m[:, None] * v).sum(axis=0), p0, rtol=1e-12, atol=1e-15)


def test_overlap_allowance_pushes_only_beyond_it_and_shrinks():
    # A pair overlapping by 0.3 mm with an allowance of 0.2 mm on one of them
    # pushes by k (0.3 - 0.2) mm (max of the two allowances, symmetric: the
    # momentum stays balanced); the kernel reports the raw overlap 0.3 mm.
    # ParticleContact keeps a newborn particle's birth overlap as its
    # allowance (no force at birth) and shrinks it as the pair separates.
    x, m, size, kb, body = _pair(-0.3e-3)
    nl = build_neighbours(x, size, 1.0, 0.0, 2)
    a = np.zeros((2, 3))
    over = np.zeros(2)
    particle_contact(x, m, size, kb, body, TL, 2, nl.offsets, nl.idx, 0.5, 1.0,
                     np.array([0.0, 0.2e-3]), over, a)
    assert np.isclose(m[1] * a[1, 0], 0.5 * 2e9 * 0.1e-3, rtol=1e-12)
    assert np.isclose(m[0] * a[0, 0], -m[1] * a[1, 0], rtol=1e-14)
    assert np.allclose(over, 0.3e-3, rtol=1e-12)
    a[:] = 0.0
    particle_contact(x, m, size, kb, body, TL, 2, nl.offsets, nl.idx, 0.5, 1.0,
                     np.array([0.3e-3, 0.0]), over, a)
    assert np.all(a == 0.0)


def test_particles_born_inside_the_contact_distance_get_no_kick():
    from sphdyn.build import build_stepper
    from sphdyn.deck import loads_deck
    from sphdyn.events.inject import InjectParticles
    from sphdyn.interactions.contact import ParticleContact

    from decks import STEEL

    deck = loads_deck(f"""
[run]
dimension = 2
t_end = "1 ms"
{STEEL}
[[body]]
name = "a"
material = "steel"
dx = "1 mm"
formulation = "total_lagrangian"
geometry = {{ shape = "box", lo = [0, 0], hi = ["4 mm", "4 mm"] }}
[[body]]
name = "b"
material = "steel"
dx = "1 mm"
geometry = {{ shape = "box", lo = [0, "4 mm"], hi = ["4 mm", "8 mm"] }}
[output]
progress = false
vtk = false
""")
    s = build_stepper(deck)
    contact = next(i for i in s.interactions if isinstance(i, ParticleContact))
    p = s.parts[0].p
    assert not contact.allow.any()  # none at the start
    # a particle of body b born 0.4 mm above a's top row (contact distance
    # 1 mm): overlap 0.6 mm with the particle below it
    top = np.flatnonzero(np.isclose(p.x[:, 1], 3.5e-3) & np.isclose(p.x[:, 0], 1.5e-3))[0]
    n = p.n
    template = int(np.flatnonzero(p.body == 1)[0])
    InjectParticles("born", 0.0, p.x[top] + [0.0, 0.4e-3, 0.0], (0.0, 0.0, 0.0),
                    template).apply(s)
    assert p.n == n + 1 and p.body[n] == 1
    assert np.isclose(contact.allow[n], 0.6e-3, rtol=1e-12)
    a = np.zeros((p.n, 3))
    contact.forces(0.0, 1e-8, a)
    assert np.all(a[n] == 0.0) and np.all(a[top] == 0.0)
    p.x[n, 1] += 0.1e-3  # moved apart: the allowance shrinks to the overlap
    contact.update_geometry(0.0)
    contact.forces(0.0, 1e-8, a)
    assert np.isclose(contact.allow[n], 0.5e-3, rtol=1e-12)
