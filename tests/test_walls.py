"""Penalty springs of the rigid wall against their formulas (Hušek et al. 2017,
eq. 8 and 9; docstring of sphdyn.interactions.wall_contact).

The whole-run wall tests (tests/test_verification.py) check bounces and
energy with tolerances of a few per cent; these pin the spring itself, so
that a missing alpha (a 10x stiffer wall) or a wrong exponent fails.
"""

from types import SimpleNamespace

import numpy as np
import pytest

from sphdyn.interactions import Wall, WallSpec
from sphdyn.interactions.wall_contact import STIFFNESS_BULK, STIFFNESS_MASS, wall_contact
from sphdyn.state import Particles

THICKNESS = 0.5
DT = 2e-7


def _cloud(dim, seed=0):
    """Six particles near a tilted wall through the origin: unequal masses,
    volumes, reference densities and bulk moduli; the last two out of reach."""
    rng = np.random.default_rng(seed)
    n = 6
    normal = np.array([0.3, 1.0, 0.4 if dim == 3 else 0.0])
    normal /= np.linalg.norm(normal)
    dx = 1e-3 * (1.0 + 0.2 * rng.uniform(-1, 1, n))
    vol0 = dx**dim
    rho0 = 2400.0 * (1.0 + 0.1 * rng.uniform(-1, 1, n))
    # masses that are not rho0 V (a random mass field), one of them zero
    m = rho0 * vol0 * np.array([1.0, 0.5, 1.7, 0.0, 1.0, 1.0])
    kbulk = 20e9 * (1.0 + 0.3 * rng.uniform(-1, 1, n))
    # gaps along the normal: inside the thickness for the first four
    gap = THICKNESS * dx * np.array([0.2, 0.5, 0.9, 0.6, 1.1, 3.0])
    tangent = np.array([1.0, -0.3, 0.0])
    tangent -= (tangent @ normal) * normal
    x = gap[:, None] * normal + rng.uniform(-1, 1, n)[:, None] * 1e-3 * tangent
    if dim == 2:
        x[:, 2] = 0.0
    return dict(x=x, m=m, vol0=vol0, rho0=rho0, kbulk=kbulk, normal=normal, dim=dim)


def _penetration(c):
    """delta_i = t_i - g_i with t_i = f_t V_i^(1/d) and g_i = x_i . n (wall at 0)."""
    return THICKNESS * c["vol0"] ** (1.0 / c["dim"]) - c["x"] @ c["normal"]


def _expected_acceleration(c, method, alpha):
    """Normal contact acceleration written out from the paper's springs.

    mass (eq. 8): k = alpha m / dt^2 acting on m, so a = alpha delta / dt^2;
    bulk (eq. 9): k = alpha K A / L with A = V^((d-1)/d), L = V^(1/d),
    acting on the nominal inertia rho0 V, so a = k delta / (rho0 V).
    Zero where delta <= 0.
    """
    pen = _penetration(c)
    d, vol = c["dim"], c["vol0"]
    if method == STIFFNESS_MASS:
        an = alpha * pen / DT**2
    else:
        area, length = vol ** ((d - 1.0) / d), vol ** (1.0 / d)
        k = alpha * c["kbulk"] * area / length
        an = k * pen / (c["rho0"] * vol)
    an = np.where(pen > 0.0, an, 0.0)
    return an[:, None] * c["normal"]


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("method,alpha", [(STIFFNESS_MASS, 0.1), (STIFFNESS_MASS, 0.35),
                                          (STIFFNESS_BULK, 0.5), (STIFFNESS_BULK, 2.0)])
def test_spring_acceleration_and_force_match_the_paper(dim, method, alpha):
    # Without friction the acceleration is normal, alpha delta / dt^2 (mass)
    # or alpha K A/L delta / (rho0 V) (bulk), and the force is m a (zero for
    # the zero-mass particle). The result is **added** to a_contact (filled
    # with 7 beforehand). Two alphas per law: the spring is linear in alpha.
    # Tolerance: round-off only (1e-12 relative; the kernel evaluates the
    # same products in another order).
    c = _cloud(dim)
    pen = _penetration(c)
    assert np.array_equal(pen > 0, [True, True, True, True, False, False])
    a = np.full((6, 3), 7.0)
    f = np.full((6, 3), 7.0)
    count = wall_contact(c["x"], np.zeros((6, 3)), c["m"], c["vol0"], c["rho0"], c["kbulk"],
                         dim, np.zeros(3), c["normal"], np.zeros(3), THICKNESS, method, alpha,
                         0.0, DT, a, f)
    expect = _expected_acceleration(c, method, alpha)
    assert count == 4
    scale = np.abs(expect).max()
    assert np.abs(a - 7.0 - expect).max() < 1e-12 * scale
    assert np.abs(f - c["m"][:, None] * expect).max() < 1e-12 * scale * c["m"].max()
    assert np.all(f[3] == 0.0) and np.abs(a[3] - 7.0).max() > 0.0  # zero mass: pushed, no force


@pytest.mark.parametrize("dim", [1, 2, 3])
def test_contact_decided_at_the_thickness_edge_as_the_formula_says(dim):
    # The kernel rejects far particles by gap^d > 1.000001 f^d V before it
    # takes the root t = f V^(1/d). Particles within 1e-3 .. 1e-15 relative
    # of the edge, on both sides, must be in contact exactly when
    # t - gap > 0 as NumPy evaluates it (same bits: the root and the
    # subtraction are the kernel's), and far ones (gap 1.01 t) out.
    rng = np.random.default_rng(dim)
    n = 400
    vol0 = (1e-3 * rng.uniform(0.5, 2.0, n)) ** dim
    t = THICKNESS * vol0 ** (1.0 / dim)
    rel = np.concatenate([rng.choice([-1.0, 1.0], n - 20) * 10.0 ** rng.uniform(-15, -3, n - 20),
                          np.full(10, 0.01), np.zeros(10)])
    gap = t * (1.0 + rel)
    x = np.zeros((n, 3))
    x[:, 1] = gap
    one = np.ones(n)
    a, f = np.zeros((n, 3)), np.zeros((n, 3))
    count = wall_contact(x, np.zeros((n, 3)), one, vol0, 2400.0 * one, 1e10 * one, dim,
                         np.zeros(3), np.array([0.0, 1.0, 0.0]), np.zeros(3), THICKNESS,
                         STIFFNESS_MASS, 0.1, 0.0, DT, a, f)
    touching = (THICKNESS * vol0 ** (1.0 / dim) - gap) > 0.0
    assert 0 < touching.sum() < n - 10
    assert count == touching.sum()
    assert np.array_equal(a[:, 1] > 0.0, touching)


def test_mass_spring_in_numbers():
    # The mass-based law in plain numbers, independent of the helper above:
    # alpha = 0.1, dt = 1e-7 s, penetration 0.1 mm -> a = 0.1 * 1e-4 / 1e-14
    # = 1e9 m/s^2 along the normal; m = 2e-3 kg -> F = 2e6 N. The bulk law:
    # 2D, V = 1e-6 m^2, K = 1e10 Pa, alpha = 0.5 -> k = alpha K (A/L = 1 in
    # 2D) = 5e9 N/m^2, rho0 V = 2.4e-3 kg/m -> a = 5e9 * 1e-4 / 2.4e-3.
    x = np.array([[0.0, 0.4e-3, 0.0]])  # thickness 0.5 * 1 mm, gap 0.4 mm
    normal = np.array([0.0, 1.0, 0.0])
    one = np.ones(1)
    for method, alpha, an in ((STIFFNESS_MASS, 0.1, 1e9),
                              (STIFFNESS_BULK, 0.5, 5e9 * 1e-4 / 2.4e-3)):
        a, f = np.zeros((1, 3)), np.zeros((1, 3))
        wall_contact(x, np.zeros((1, 3)), 2e-3 * one, 1e-6 * one, 2400.0 * one, 1e10 * one,
                     2, np.zeros(3), normal, np.zeros(3), 0.5, method, alpha, 0.0, 1e-7, a, f)
        assert a[0, 1] == pytest.approx(an, rel=1e-12)
        assert f[0, 1] == pytest.approx(2e-3 * an, rel=1e-12)
        assert a[0, 0] == a[0, 2] == 0.0


@pytest.mark.parametrize("method,bulk", [("mass", None), ("bulk", None), ("bulk", 3e9)])
def test_wall_interaction_passes_its_spring_to_the_kernel(method, bulk):
    # Through the Wall interaction (wall.py): the deck's alpha, the wall's
    # own bulk modulus when given (else each particle's), the step dt, and
    # the total force is the sum of m a. Same formulas, round-off tolerance.
    c = _cloud(2, seed=1)
    p = Particles.allocate(6, 2)
    p.x, p.m, p.vol0, p.rho0 = c["x"], c["m"], c["vol0"], c["rho0"]
    p.add("bulk_modulus", ())
    p.bulk_modulus = c["kbulk"]
    alpha = 0.3
    spec = WallSpec("w", np.zeros(3), c["normal"], {"mass": STIFFNESS_MASS,
                                                     "bulk": STIFFNESS_BULK}[method],
                    alpha, 0.0, THICKNESS, bulk_modulus=bulk)
    w = Wall(spec, SimpleNamespace(p=p))
    a = np.zeros((6, 3))
    w.forces(0.0, DT, a)
    if bulk is not None:
        c["kbulk"] = np.full(6, bulk)
    expect = _expected_acceleration(c, spec.method, alpha)
    scale = np.abs(expect).max()
    assert np.abs(a - expect).max() < 1e-12 * scale
    total = (c["m"][:, None] * expect).sum(axis=0)
    assert np.abs(w.total - total).max() < 1e-12 * np.abs(total).max()
    assert w.columns(0.0)["F_wall_w"] == pytest.approx(total @ c["normal"], rel=1e-12)
    assert w.count == 4
