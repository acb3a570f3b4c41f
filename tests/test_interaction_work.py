"""The work of each interaction booked apart (``[output] interaction_work``,
:mod:`sphdyn.watchers.interaction_work`).

What is pinned here: the kick's work sum of one source against NumPy (slaves
left out); in an impact with erosion into particles (a wall on the elements,
the same wall on the particles, the penalty coupling, gravity), the sources'
columns add up to ``-E_contact`` to round-off, the erosion's change of the
loads is a source of its own, gravity (external work) is not among them, and
the books change nothing of the motion; a run restarted from a checkpoint
books the same bits; two interactions with one name are refused.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest

from sphdyn.watchers.interaction_work import kick_work
from sphdyn.interactions import Gravity
from sphdyn.state import BC_FIXED, BC_SLAVE
from test_erosion import _impact


def test_kick_work_is_the_mass_weighted_power_over_the_kick():
    rng = np.random.default_rng(3)
    n = 50
    a, v = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    m = rng.uniform(0.5, 2.0, n)
    bc = np.zeros(n, dtype=np.int8)
    bc[::7] = BC_SLAVE
    bc[3] = BC_FIXED  # booked: a fixed node's mean velocity is the kick's
    dt = 2.5e-7
    free = bc != BC_SLAVE
    expected = dt * np.sum(m[free] * np.sum(a[free] * v[free], axis=1))
    got = kick_work(a, m, bc, v, dt)
    assert got == pytest.approx(expected, rel=1e-13)


def _gravity(solid):
    return Gravity(solid, np.array([0.0, 0.0, -9.81e3]))  # strong enough to show


def test_the_sources_add_up_to_the_interactions_work_through_erosion():
    """400 steps of the erosion impact of test_erosion.py, with gravity: the
    books are ``W_contact_<name>`` for the two walls and the coupling, and
    ``W_contact_events``; their sum is ``-E_contact`` to 1e-10 of the largest
    (round-off of a few thousand kicks; the sums differ in order only)."""
    st, ev = _impact("particles", interaction_work=True, others=(_gravity,))
    ref, _ = _impact("particles", others=(_gravity,))
    for _ in range(400):
        st.step()
        ref.step()
    assert ev.eroded > 0
    rec = st.record()
    cols = {k: v for k, v in rec.items() if k.startswith("W_contact_")}
    names = [i.name for i in st.interactions]
    assert sorted(cols) == sorted(["W_contact_events"]
                                  + [f"W_contact_{n}" for n in names if "gravity" not in n])
    scale = max(abs(v) for v in cols.values())
    assert scale > 1.0  # [J]: the wall stops a 20 m/s block of 154 g
    assert abs(sum(cols.values()) + rec["E_contact"]) < 1e-10 * scale
    assert abs(cols["W_contact_events"]) > 1e-6 * scale  # erosion moved loads
    assert cols["W_contact_c"] != 0.0  # the coupling met the particles
    # the books watch, they do not act
    for name, arr in st.parts[1].p.arrays().items():
        assert np.array_equal(arr, getattr(ref.parts[1].p, name)), name
    assert rec["E_total"] == ref.record()["E_total"]


def test_a_restored_run_books_the_same_bits():
    st, ev = _impact("particles", interaction_work=True)
    for _ in range(150):
        st.step()
    assert ev.eroded > 0
    scalars, groups = copy.deepcopy(st.state())
    st2, _ = _impact("particles", interaction_work=True)
    st2.restore(scalars, groups)
    for _ in range(60):
        st.step()
        st2.step()
    a, b = st.record(), st2.record()
    for k in a:
        if k.startswith("W_contact_"):
            assert a[k] == b[k], k
    plain, _ = _impact("particles")
    with pytest.raises(ValueError, match="interaction_work"):
        st3, _ = _impact("particles", interaction_work=True)
        st3.restore(*copy.deepcopy(plain.state()))


def test_two_interactions_with_one_name_are_refused():
    """Their checkpoint groups (``interaction.<name>``) and columns would collide."""
    from sphdyn.interactions import Wall

    def second_floor(solid):
        return Wall(_impact("nothing")[0].interactions[0].spec, solid)  # named "floor"

    with pytest.raises(ValueError, match="two interactions are named 'floor'"):
        _impact("nothing", others=(second_floor,))
