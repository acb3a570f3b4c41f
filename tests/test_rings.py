"""Colliding rubber rings (Gray, Monaghan & Swift 2001; thesis sec. 3.2) at reduced
resolution: the tensile instability breaks the rings of plain updated-Lagrangian
SPH, the artificial stress (Monaghan 2000) keeps them intact and they bounce.
Also the fragment counting of :mod:`sphdyn.analysis.fragments` used as the measure.

Resolution: dx = 1.5 mm (7 particles across the 10 mm wall, 976 per ring)
and h = 1.2 dx as in the thesis. With h = 1.5 dx (Gray et al.) at this dx
the rings only crack (fragments within one support of each other); at
dx = 1 mm, h = 1.5 dx they break apart too (see docs/tensile-instability.md).

Fracture measure: fragments linked at 1.5 dx, i.e. a crack is a gap wider
than 1.5 dx between particles of the same ring. Intact rings strain by
about v/c = 7.52/145 = 5 %, so 1.5 dx is far from any elastic stretch; the
2h link (no interaction at all) is not robust because broken pieces of a ring
are pushed back into contact during the collision. The largest fragment's
share of a ring is reported besides the count, as single spalled particles
would otherwise count as fragments.
"""

import numpy as np
import pytest

from sphdyn.analysis.fragments import count_fragments, fragment_labels, fragment_sizes
from sphdyn.deck import loads_deck
from sphdyn.geometry import box_lattice
from stepping import build_stepper

DX = 1.5e-3
V0 = 7.52  # impact speed of each ring [m/s] (Gray et al.'s 0.059 c0)

RINGS = """
[run]
dimension = 2
t_end = 0.02
[sph]
h_factor = 1.2
artificial_stress = {{ epsilon = {eps} }}
[[material]]
name = "rubber"
model = "elastic"
density = 1000.0
E = 1.0e7
nu = 0.3975
[[body]]
name = "left"
material = "rubber"
dx = {dx}
velocity = [{v}, 0]
geometry = {{ shape = "ring", centre = [-0.041, 0], inner_radius = 0.03, outer_radius = 0.04 }}
[[body]]
name = "right"
material = "rubber"
dx = {dx}
velocity = [-{v}, 0]
geometry = {{ shape = "ring", centre = [0.041, 0], inner_radius = 0.03, outer_radius = 0.04 }}
"""


# ------------------------------------------------------- fragment counting
def _block(lo, n=(5, 4), dx=1e-3):
    return box_lattice([lo[0], lo[1], 0], [lo[0] + n[0] * dx, lo[1] + n[1] * dx, 0], dx,
                       2)


def test_fragments_one_lattice_is_one_fragment_and_a_gap_splits_it():
    a = _block((0, 0))
    b = _block((5 * 1e-3 + 1e-3, 0))  # next column 2 dx away from the last of a
    x = np.vstack([a, b])
    assert count_fragments(a, 1.5 * 1e-3) == 1
    assert count_fragments(x, 1.5 * 1e-3) == 2  # 2 dx gap > link 1.5 dx
    assert count_fragments(x, 2.5 * 1e-3) == 1  # ... < 2.5 dx
    lab = fragment_labels(x, 1.5 * 1e-3)
    assert set(lab[: len(a)]) == {lab[0]} and set(lab[len(a):]) == {lab[-1]}
    assert sorted(fragment_sizes(lab)) == [20, 20]


def test_fragments_link_is_strict_and_per_particle_lengths_use_the_pair_mean():
    x = np.array([[0.0, 0.0], [1.0, 0.0]])
    assert count_fragments(x, 1.0) == 2  # r < d is required
    assert count_fragments(x, 1.0 + 1e-9) == 1
    assert count_fragments(x, np.array([0.5, 1.6])) == 1  # mean 1.05
    assert count_fragments(x, np.array([0.5, 1.4])) == 2  # mean 0.95


def test_fragments_per_body_counts_do_not_link_different_bodies():
    a = _block((0, 0))
    b = _block((5 * 1e-3, 0))  # touching a (spacing dx)
    x = np.vstack([a, b])
    body = np.r_[np.zeros(len(a), int), np.ones(len(b), int)]
    assert count_fragments(x, 1.5 * 1e-3) == 1
    assert count_fragments(x, 1.5 * 1e-3, body) == {0: 1, 1: 1}
    # break body 1 into two by moving its top row far away
    x2 = x.copy()
    top = (body == 1) & (x[:, 1] > 3 * 1e-3)
    x2[top, 1] += 10 * 1e-3
    assert count_fragments(x2, 1.5 * 1e-3, body) == {0: 1, 1: 2}


def test_fragments_min_size_and_mask():
    a = _block((0, 0))
    x = np.vstack([a, [[0.1, 0.1, 0.0]]])  # one far particle
    assert count_fragments(x, 1.5 * 1e-3) == 2
    assert count_fragments(x, 1.5 * 1e-3, min_size=2) == 1
    mask = np.ones(len(x), bool)
    mask[-1] = False
    assert count_fragments(x, 1.5 * 1e-3, mask=mask) == 1
    assert fragment_labels(x, 1.5 * 1e-3, mask=mask)[-1] == -1


# ------------------------------------------------------------------- rings
def _rings(eps):
    d = loads_deck(RINGS.format(eps=eps, dx=DX, v=V0))
    return build_stepper(d)


def _left_velocity(s):
    left = s.part("sph").kin.body == 0
    return float((s.part("sph").kin.m[left] * s.part("sph").kin.v[left, 0]).sum() / s.part("sph").kin.m[left].sum())


def _largest_share(s):
    """Smallest over the rings of (largest fragment) / (ring particles), link 1.5 dx."""
    p = s.part("sph").kin
    lab = fragment_labels(p.x, 1.5 * DX, p.body)
    sizes = fragment_sizes(lab)
    return min(sizes[np.unique(lab[p.body == b])].max() / (p.body == b).sum()
               for b in (0, 1))


def _run(s, t):
    while s.t < t:
        s.step()


@pytest.mark.slow
def test_plain_sph_rings_fracture():
    # measured: intact at 4 ms; at 5 ms 4 fragments per ring (2 at a 2h
    # link), at 6.5 ms 6 (4 at 2h), the largest holds 61 % of its ring and the
    # left ring still moves at +1.99 m/s = +0.27 V0 (no rebound; with the
    # remedy it is at -1.18 m/s by then); ~1000 of 1952 particles flagged by
    # the Swegle indicator. Thresholds: >= 3 fragments and < 80 % in the
    # largest, far from the intact values (1 and 100 %).
    s = _rings(0.0)
    _run(s, 6.5e-3)
    frags = count_fragments(s.part("sph").kin.x, 1.5 * DX, s.part("sph").kin.body)
    assert min(frags.values()) >= 3, frags
    assert _largest_share(s) < 0.8
    assert _left_velocity(s) > 0.1 * V0  # still approaching: no rebound
    assert s.record(kinetic=0.0, dt=0.0)["swegle_unstable"] > 0


@pytest.mark.slow
def test_artificial_stress_keeps_rings_intact_and_they_bounce():
    # Gray et al. (2001) with epsilon = 0.3, n = 4. Measured: both rings one
    # fragment throughout, contact over by ~10.3 ms, left ring then at
    # -5.58 m/s = -0.74 V0 (restitution 0.74; the rest of the kinetic energy
    # stays in ring vibration). Threshold: rebound faster than 0.6 V0.
    s = _rings(0.3)
    e0 = s.record(kinetic=s.kinetic_now(), dt=0.0)["E_total"]
    t_check = [2e-3, 4e-3, 6e-3, 8e-3, 10.5e-3]
    for t in t_check:
        _run(s, t)
        assert count_fragments(s.part("sph").kin.x, 1.5 * DX, s.part("sph").kin.body) == {0: 1, 1: 1}, t
    v1 = _left_velocity(s)
    _run(s, 11e-3)
    v2 = _left_velocity(s)
    assert v1 < -0.6 * V0
    assert abs(v2 - v1) < 1e-3 * V0  # rings apart: momentum of each ring constant
    # the artificial-stress work is booked as heat, so the energy closes
    # (measured -0.06 % over 11 ms; -2.5 % before it was booked); 1.5 % as
    # for the total-Lagrangian rings
    rec = s.record(kinetic=s.kinetic_now(), dt=0.0)
    assert abs(rec["E_total"] - e0) < 0.015 * e0
    # separated by more than the support radius 2 h
    xl = s.part("sph").kin.x[s.part("sph").kin.body == 0, 0].max()
    xr = s.part("sph").kin.x[s.part("sph").kin.body == 1, 0].min()
    assert xr - xl > 2 * s.part("sph").kin.h.max()


# ------------------------------------------------------- total-Lagrangian rings
def _tl_rings(contact=None, hourglass=10.0, update=0):
    extra = (f'formulation = "total_lagrangian"\nhourglass_coefficient = {hourglass}\n'
             f'reference_update_every = {update}')
    deck = RINGS.format(eps=0.0, dx=DX, v=V0).replace("[sph]", "[sph]\n" + extra)
    if contact is not None:
        deck += f"[contact]\nenabled = {str(contact).lower()}\n"
    d = loads_deck(deck)
    return build_stepper(d)


@pytest.mark.slow
def test_total_lagrangian_rings_bounce_back_intact():
    # Thesis sec. 3.2, Fig. 3.4: with the total-Lagrangian kernel the rings
    # cannot fracture numerically; they meet through the particle contact.
    # Measured (dx 1.5 mm, h 1.2 dx, hourglass 10): one fragment per ring at
    # every ms, contact over by 9 ms, left ring then at -0.804 V0; total
    # energy within 0.7 % of the impact energy (contact springs, viscosity
    # and hourglass work included). Thresholds: rebound faster than 0.7 V0
    # (the artificial-stress run reaches 0.74 V0), energy within 1.5 %.
    s = _tl_rings()
    e0 = s.record(kinetic=s.kinetic_now(), dt=0.0)["E_total"]
    for t in (2e-3, 4e-3, 6e-3, 8e-3, 10e-3):
        _run(s, t)
        assert count_fragments(s.part("sph").kin.x, 1.5 * DX, s.part("sph").kin.body) == {0: 1, 1: 1}, t
    v1 = _left_velocity(s)
    _run(s, 10.5e-3)
    rec = s.record(kinetic=s.kinetic_now(), dt=0.0)
    assert v1 < -0.7 * V0
    assert abs(_left_velocity(s) - v1) < 1e-3 * V0  # apart: momentum constant
    assert abs(rec["E_total"] - e0) < 0.015 * e0
    assert rec["contacts_bodies"] == 0
    assert rec["swegle_unstable"] == 0  # no updated-Lagrangian particle


def test_total_lagrangian_rings_need_contact():
    # Without [contact] the fixed reference neighbour lists never link the two
    # rings: they pass through each other unchanged (left ring keeps +V0 while
    # the rings overlap), which is why contact is on by default for them.
    s = _tl_rings(contact=False)
    _run(s, 1.5e-3)  # rings overlap by 2 * 1.5 ms * V0 - 2 mm = 20 mm
    assert abs(_left_velocity(s) - V0) < 1e-9 * V0
    s = _tl_rings()  # default: contact on, the rings are slowed
    _run(s, 1.5e-3)
    assert _left_velocity(s) < 0.8 * V0


@pytest.mark.slow
def test_total_lagrangian_rings_with_reference_updates():
    # The same rings with the reference configuration renewed every 100 steps
    # (about 0.5 ms, 30 updates): still two intact rings that bounce.
    # Measured: rebound -0.71 V0 (fixed reference: -0.80), energy +2.9 % (each
    # update restarts F and the hourglass reference, about 0.1 % per update
    # here). Thresholds: rebound faster than 0.6 V0, energy within 4 %.
    s = _tl_rings(update=100)
    e0 = s.record(kinetic=s.kinetic_now(), dt=0.0)["E_total"]
    _run(s, 10.5e-3)
    assert s.part("sph").tl.n_updates >= 25
    assert count_fragments(s.part("sph").kin.x, 1.5 * DX, s.part("sph").kin.body) == {0: 1, 1: 1}
    rec = s.record(kinetic=s.kinetic_now(), dt=0.0)
    assert _left_velocity(s) < -0.6 * V0
    assert abs(rec["E_total"] - e0) < 0.04 * e0
