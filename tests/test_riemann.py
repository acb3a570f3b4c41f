"""The exact Riemann solution (sphdyn.analysis.riemann) against Toro's published
values (Riemann Solvers and Numerical Methods for Fluid Dynamics, 3rd ed.,
Table 4.3: star pressure, velocity and densities as printed, to half a unit
of their last digit)."""

from __future__ import annotations

import numpy as np
import pytest

from sphdyn.analysis.riemann import sample, shock_speed, star_state

# (left, right, p*, u*, rho*_L, rho*_R) as printed, gamma = 1.4
TORO = [
    ((1.0, 0.0, 1.0), (0.125, 0.0, 0.1), "0.30313", "0.92745", "0.42632", "0.26557"),
    ((1.0, -2.0, 0.4), (1.0, 2.0, 0.4), "0.00189", "0.00000", "0.02185", "0.02185"),
    ((1.0, 0.0, 1000.0), (1.0, 0.0, 0.01), "460.894", "19.5975", "0.57506", "5.99924"),
]


def _printed(text):
    """``pytest.approx`` of a printed value within half a unit of its last digit."""
    decimals = len(text.split(".")[1])
    return pytest.approx(float(text), abs=0.5 * 10.0 ** -decimals, rel=0)


@pytest.mark.parametrize("left,right,ps,us,rl,rr", TORO, ids=["sod", "123", "blast"])
def test_star_state_matches_toro(left, right, ps, us, rl, rr):
    # the star densities sampled just left and right of the contact at t = 1
    p, u = star_state(left, right, 1.4)
    assert p == _printed(ps) and u == _printed(us)
    rho = sample(np.array([u - 1e-9, u + 1e-9]), 1.0, left, right, 1.4)[0]
    assert rho[0] == _printed(rl) and rho[1] == _printed(rr)


def test_far_field_is_the_initial_states_and_mirror_symmetry():
    left, right = (1.0, 0.0, 1.0), (0.125, 0.0, 0.1)
    out = sample(np.array([-10.0, 10.0]), 1.0, left, right, 1.4)
    assert np.allclose(out[:, 0], left) and np.allclose(out[:, 1], right)
    # the mirrored problem is the same solution mirrored
    x = np.linspace(-0.5, 0.5, 41)
    a = sample(x, 0.2, left, right, 1.4)
    b = sample(-x, 0.2, (0.125, 0.0, 0.1), (1.0, 0.0, 1.0), 1.4)
    assert np.allclose(a[0], b[0]) and np.allclose(a[1], -b[1]) and np.allclose(a[2], b[2])
    # the shock: the density jump at x = 0.2 * shock speed
    xs = 0.2 * shock_speed(left, right, 1.4)
    assert sample(np.array([xs - 1e-9]), 0.2, left, right, 1.4)[0, 0] > 0.26
    assert sample(np.array([xs + 1e-9]), 0.2, left, right, 1.4)[0, 0] == 0.125
