"""Verification of the solid elements (hex8, plane-strain quad4): exact volume
derivatives, patch tests, rigid rotation, hourglass and bulk-viscosity
coefficients against their formulas, the stable step, the bar wave speed and
energy conservation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fem_models import block, material, part
from sphdyn.geometry.shapes import (corner_signs, gauss_derivatives, hourglass_vectors,
                                     volume_table)
from sphdyn.parts.fem.solid import volume_gradient
from sphdyn.state import BC_VELOCITY
from sphdyn.stepper import Stepper
from stepping import step

STEEL = dict(density=7850.0, E=210e9, nu=0.3)


def gauss_volume(xe, dim):
    """Exact volume of a trilinear (bilinear) element: 2^d Gauss points of det J."""
    return sum(np.linalg.det(xe[:, :dim].T @ d) for d in gauss_derivatives(dim))


def distorted(dim, rng, amount=0.15):
    """Corners of a unit element moved at random by up to ``amount``."""
    xe = np.zeros((2 ** dim, 3))
    xe[:, :dim] = 0.5 * corner_signs(dim) + rng.uniform(-amount, amount, (2 ** dim, dim))
    return xe


def distorted_block(dim, div, rng, amount=0.2):
    """A block whose interior nodes are moved by up to ``amount`` of the spacing."""
    x, cells = block([0, 0, 0], [1, 1, 1], div, dim)
    h = 1.0 / np.array(div[:dim])
    inner = np.all((x[:, :dim] > 1e-9) & (x[:, :dim] < 1 - 1e-9), axis=1)
    x[inner, :dim] += rng.uniform(-amount, amount, (inner.sum(), dim)) * h
    return x, cells


# ----------------------------------------------------------------- geometry
@pytest.mark.parametrize("dim", [2, 3])
def test_volume_gradient_is_the_derivative_of_the_exact_volume(dim):
    """The 1/12 (1/2) table gives the Gauss volume (to round-off) and its
    derivatives match central differences (step 1e-6: truncation error ~1e-12,
    so a 1e-8 tolerance catches any wrong sign or factor)."""
    rng = np.random.default_rng(1)
    xe = distorted(dim, rng)
    tab = volume_table(dim)
    g = np.zeros((2 ** dim, 3))
    V = volume_gradient(xe, dim, tab, g)
    assert V == pytest.approx(gauss_volume(xe, dim), rel=1e-13)
    h = 1e-6
    for I in range(2 ** dim):
        for k in range(dim):
            xp, xm = xe.copy(), xe.copy()
            xp[I, k] += h
            xm[I, k] -= h
            fd = (gauss_volume(xp, dim) - gauss_volume(xm, dim)) / (2 * h)
            assert g[I, k] == pytest.approx(fd, abs=1e-8)


def test_generated_hex_gradient_is_up_to_date(tmp_path, monkeypatch):
    """src/sphdyn/parts/fem/hex_gradient.py is what tools/gen_hex_gradient.py
    writes from the current volume table."""
    import importlib.util
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    spec = importlib.util.spec_from_file_location("gen", root / "tools/gen_hex_gradient.py")
    gen = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(gen)
    monkeypatch.setattr(gen, "OUT", tmp_path / "hex_gradient.py")
    gen.main()
    assert (tmp_path / "hex_gradient.py").read_text() == \
        (root / "src/sphdyn/parts/fem/hex_gradient.py").read_text()


@pytest.mark.parametrize("dim", [2, 3])
def test_hourglass_vectors_are_orthogonal_to_linear_fields(dim):
    s = corner_signs(dim)
    base = np.column_stack([np.ones(2 ** dim), s])
    G = hourglass_vectors(dim)
    assert G.shape == ({2: 1, 3: 4}[dim], 2 ** dim)
    assert np.abs(G @ base).max() == 0.0
    assert np.linalg.matrix_rank(np.vstack([base.T, G])) == 2 ** dim


# --------------------------------------------------------------- patch tests
@pytest.mark.parametrize("integration", ["one_point", "selective_reduced"])
@pytest.mark.parametrize("dim", [2, 3])
def test_patch_linear_velocity_gives_exact_constant_rate(dim, integration):
    """A linear velocity field on a distorted mesh gives the same velocity
    gradient at every integration point, to round-off (1e-12 relative)."""
    rng = np.random.default_rng(2)
    x, cells = distorted_block(dim, (3, 3, 3)[:dim], rng)
    p = part(x, cells, dim, integration=integration)
    A = np.zeros((3, 3))
    A[:dim, :dim] = rng.normal(size=(dim, dim))
    p.nodes.v = x @ A.T + 0.3
    p._geometry(0.0)
    assert np.abs(p.pts.L - A).max() < 1e-12 * np.abs(A).max()


@pytest.mark.parametrize("integration", ["one_point", "selective_reduced"])
@pytest.mark.parametrize("dim", [2, 3])
def test_patch_constant_stress_balances_interior_nodes(dim, integration):
    """Constant stress in a distorted mesh: the nodal forces are
    -sigma . dV/dx of the whole block, so interior nodes carry none and the
    nodes of the face x = 1 (unit area, edges included) carry -sigma . e_x in
    total. Tolerance: round-off of sums of 1e6 Pa terms (1e-9 relative)."""
    rng = np.random.default_rng(3)
    x, cells = distorted_block(dim, (3, 3, 3)[:dim], rng)
    p = part(x, cells, dim, integration=integration)
    S = np.zeros((3, 3))
    S[:dim, :dim] = np.array([[3.0, 1.0, 0.5], [1.0, -2.0, 0.7],
                              [0.5, 0.7, 1.5]])[:dim, :dim] * 1e6
    if dim == 2:
        S[2, 2] = 0.4e6  # plane strain: sigma_zz does no in-plane work
    p.pts.sig[:] = S
    p._geometry(0.0)
    p._forces(0.0)
    f = p.nodes.a * p.nodes.m[:, None]
    inner = np.all((x[:, :dim] > 1e-9) & (x[:, :dim] < 1 - 1e-9), axis=1)
    assert inner.any()
    assert np.abs(f[inner]).max() < 1e-9 * 1e6
    face = np.isclose(x[:, 0], 1.0)
    assert np.allclose(f[face].sum(axis=0), -S[:, 0], rtol=0, atol=1e-9 * 1e6)
    assert np.abs(f.sum(axis=0)).max() < 1e-9 * 1e6


@pytest.mark.parametrize("dim", [2, 3])
def test_rigid_rotation_of_90_degrees_gives_no_stress(dim):
    """Nodes moved on an exact rigid rotation (chord velocities) of a distorted
    block: the mid-step gradient is exactly skew, so the stress stays at
    round-off (below 1 Pa for E = 210 GPa) and no hourglass work is done."""
    rng = np.random.default_rng(4)
    x, cells = distorted_block(dim, (3, 3, 2)[:dim], rng)
    p = part(x, cells, dim)
    p.nodes.bc[:] = BC_VELOCITY
    X = x - x.mean(axis=0)
    omega = 50.0
    t_end = 0.5 * math.pi / omega

    def rotated(theta):
        c, s = math.cos(theta), math.sin(theta)
        R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
        return X @ R.T + x.mean(axis=0)

    class Prescribe:
        def before_step(self, st, dt, k, part_):
            dt = min(dt, t_end - st.t)  # the step is shortened to land on t_end
            p.nodes.bc_v = (rotated(omega * (st.t + dt)) - rotated(omega * st.t)) / dt

    s = Stepper([p], monitors=[Prescribe()])
    while s.t < t_end - 1e-12:
        s.step(t_stop=t_end)
    assert s.step_count > 100
    assert np.allclose(p.nodes.x, rotated(0.5 * math.pi), atol=1e-12)
    assert np.abs(p.pts.sig).max() < 1.0
    assert abs(p.hourglass_energy()) < 1e-12


def test_prestress_rotates_with_the_body():
    """A uniaxial 100 MPa stress along x, rotated 90 degrees about z in 400
    steps, ends along y: the Jaumann update's forward-Euler error is about
    n (d theta)^2 = 0.6 %, so 1 % of the stress."""
    rng = np.random.default_rng(5)
    x, cells = distorted_block(3, (2, 2, 2), rng)
    p = part(x, cells, 3, hourglass_coefficient=0.0)
    p.pts.sig[:, 0, 0] = 100e6
    p.nodes.bc[:] = BC_VELOCITY
    X = x - x.mean(axis=0)
    n_steps = 400
    dth = 0.5 * math.pi / n_steps

    def rotated(theta):
        c, s = math.cos(theta), math.sin(theta)
        return X @ np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]]).T

    class Prescribe:
        def before_step(self, st, dt, k, part_):
            p.nodes.bc_v = (rotated(dth * (st.step_count + 1))
                            - rotated(dth * st.step_count)) / dt

    s = Stepper([p], monitors=[Prescribe()])
    for _ in range(n_steps):
        s.step()
    sig = p.pts.sig
    assert np.allclose(sig[:, 1, 1], 100e6, rtol=0.01)
    assert np.abs(sig[:, 0, 0]).max() < 0.01 * 100e6
    assert np.abs(sig[:, 0, 1]).max() < 0.01 * 100e6


# -------------------------------------------------------------- coefficients
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("form", ["viscous", "stiffness"])
def test_hourglass_force_of_a_cube_matches_its_formula(dim, form):
    """A cube (square) of side a in a pure hourglass mode (x velocity u Gamma_I):
    no strain, and the forces are -Q Gamma with Q = a_h (2^d u) (viscous,
    a_h = Qhg rho c V^((d-1)/d) / 4) or Q = dt k_h (2^d u) (stiffness,
    k_h = Qhg rho c^2 V sum(b^2) / d), opposing the motion; their work is
    booked in e_hg."""
    a, u, qh, dt = 0.1, 0.5, 0.1, 1e-6
    x, cells = block([0, 0, 0], [a, a, a], (1, 1, 1)[:dim], dim)
    p = part(x, cells, dim, hourglass=form, hourglass_coefficient=qh, q1=0.0, q2=0.0)
    gam = hourglass_vectors(dim)[0]
    p.nodes.v[cells[0], 0] = u * gam
    p._geometry(0.0)
    assert np.abs(p.pts.L).max() < 1e-12  # the mode has no uniform strain
    p._forces(dt)
    f = p.el.fe[0]
    rho, c = STEEL["density"], p.pts.c[0]
    K = 210e9 / (3 * (1 - 0.6))
    G = 210e9 / 2.6
    assert c == pytest.approx(math.sqrt((K + 4 * G / 3) / rho))
    V = a ** dim
    nen = 2 ** dim
    if form == "viscous":
        Q = qh * rho * c * V ** ((dim - 1) / dim) / 4 * nen * u
    else:
        # the uniform gradient at the centre: abs(dN_I/dx_k) = 1 / (2^(d-1) a)
        bb = nen * dim / (2 ** (dim - 1) * a) ** 2
        Q = dt * qh * rho * c * c * V * bb / dim * nen * u
    assert np.allclose(f[:, 0], -Q * gam, rtol=1e-12)
    assert np.abs(f[:, 1:]).max() < 1e-12 * Q
    power = float(np.sum(f[:, 0] * p.nodes.v[cells[0], 0]))
    assert power < 0.0  # it resists the mode
    assert p.el.e_hg[0] == pytest.approx(-dt * power, rel=1e-12)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("form", ["viscous", "stiffness"])
def test_hourglass_forces_of_a_distorted_element_follow_the_shape_vectors(dim, form):
    """A distorted element with random node velocities, no stress: the forces
    are -sum_a Q_a gamma_aI with the Flanagan-Belytschko shape vectors
    gamma_aI = Gamma_aI - (sum_J Gamma_aJ x_J) . b_I evaluated directly
    (NumPy), Q_a = a_h qdot_a or dt k_h qdot_a, qdot_a = sum_I v_I gamma_aI;
    the kernel's resultant form must give the same forces and work
    (1e-12 relative: round-off of a few dozen terms)."""
    rng = np.random.default_rng(11)
    qh, dt = 0.1, 1e-6
    xe = distorted(dim, rng)
    cells = np.arange(2 ** dim)[None, :]
    p = part(xe, cells, dim, hourglass=form, hourglass_coefficient=qh, q1=0.0, q2=0.0)
    v = np.zeros((2 ** dim, 3))
    v[:, :dim] = rng.normal(size=(2 ** dim, dim))
    p.nodes.v = v
    p._geometry(0.0)
    p._forces(dt)
    g = np.zeros((2 ** dim, 3))
    V = volume_gradient(xe - xe[0], dim, volume_table(dim), g)
    b = g / V
    gam = hourglass_vectors(dim)
    shape = gam - (gam @ xe) @ b.T  # (modes, nen)
    qdot = shape @ v  # (modes, 3)
    rho, c = p.pts.rho[0], p.pts.c[0]
    if form == "viscous":
        coef = qh * rho * c * V ** ((dim - 1) / dim) / 4
    else:
        coef = qh * rho * c * c * V * np.sum(b * b) / dim * dt
    Q = coef * qdot
    if dim == 2:
        Q[:, 2] = 0.0  # plane strain: no out-of-plane hourglass force
    f = -shape.T @ Q
    assert np.allclose(p.el.fe[0], f, rtol=0, atol=1e-12 * np.abs(f).max())
    assert np.abs(f).max() > 0.0
    assert p.el.e_hg[0] == pytest.approx(dt * np.sum(Q * qdot), rel=1e-12)
    assert np.abs(shape @ xe[:, :dim]).max() < 1e-12  # orthogonal to linear fields


def test_bulk_viscosity_pressure_and_heat_match_their_formula():
    """A cube compressed at a uniform rate: q = rho l (Q1 l r^2 - Q2 c r),
    l = a / sqrt(3) (the stable-step length of the cube), acts as a pressure
    on the faces and heats the element by -q r dt / rho."""
    a, r, dt = 0.1, -200.0, 1e-7
    x, cells = block([0, 0, 0], [a, a, a], (1, 1, 1), 3)
    p = part(x, cells, 3, hourglass_coefficient=0.0)
    p.nodes.v = r / 3.0 * x  # trace of L = r
    p._geometry(0.0)
    assert np.trace(p.pts.L[0]) == pytest.approx(r)
    p._forces(dt)
    rho, c = p.pts.rho[0], p.pts.c[0]
    ell = a / math.sqrt(3)
    q = rho * ell * (1.5 * ell * r * r - 0.06 * c * r)
    # the face x = a carries the pressure q: nodal x forces sum to +q a^2 (push out)
    fx = p.el.fe[0][x[cells[0], 0] > a / 2, 0].sum()
    assert fx == pytest.approx(q * a * a, rel=1e-12)
    assert p.pts.e_av[0] == pytest.approx(-q * r * dt / rho, rel=1e-12)


def test_stable_step_of_a_cube_and_of_the_bound():
    """Cube at rest: dt = 0.9 l / (Q + sqrt(Q^2 + c^2)), l = a / sqrt 3,
    Q = Q2 c; compressed at the rate r: Q = Q2 c + Q1 l |r| (without
    hourglass control, whose terms the step takes too: the test above)."""
    a = 0.01
    x, cells = block([0, 0, 0], [a, a, a], (1, 1, 1), 3)
    p = part(x, cells, 3, hourglass_coefficient=0.0)
    c = p.pts.c[0]
    Q = 0.06 * c
    dt, k = p.stable_dt()
    assert k == 0
    assert dt == pytest.approx(0.9 * a / math.sqrt(3) / (Q + math.sqrt(Q * Q + c * c)),
                               rel=1e-12)
    # in compression the bulk viscosity adds Q1 l |eps_kk| to Q
    r = -500.0
    p.nodes.v = r / 3.0 * x
    p._geometry(0.0)
    p._forces(0.0)  # the element steps come with the force pass
    ell = a / math.sqrt(3)
    Q = 0.06 * c + 1.5 * ell * abs(r)
    assert p.stable_dt()[0] == pytest.approx(0.9 * ell / (Q + math.sqrt(Q * Q + c * c)),
                                             rel=1e-12)


# ------------------------------------------------------------ wave dynamics
def free_bar_mode(integration="one_point", dim=3, periods=1.0):
    """First free-free mode of a bar (L = 1 m, c = 1000 m/s, nu = 0): its
    period from the end's displacement and the energy records."""
    div = (40, 2, 2)[:dim]
    x, cells = block([0, 0, 0], [1.0, 0.05, 0.05], div, dim)
    mat = material(density=1000.0, E=1e9, nu=0.0)
    p = part(x, cells, dim, mat=mat, integration=integration)
    p.nodes.v[:, 0] = 1e-3 * np.cos(np.pi * x[:, 0])
    s = Stepper([p])
    T, u, E = [], [], []
    while s.t < periods * 2e-3:
        r = step(s)
        T.append(r["time"])
        E.append(r["E_total"])
        u.append(p.nodes.x[0, 0] - p.nodes.x0[0, 0])
    T, u, E = map(np.array, (T, u, E))
    crossings = T[1:][np.diff(np.sign(u - u.mean())) != 0]
    return 2 * np.mean(np.diff(crossings)), E


@pytest.mark.parametrize("integration", ["one_point", "selective_reduced"])
@pytest.mark.parametrize("dim", [2, 3])
def test_bar_wave_speed_and_energy_over_ten_periods(dim, integration):
    """Free-free bar, 40 elements along (nu = 0, so c = sqrt(E/rho) = 1000 m/s
    in 3D and in plane strain): the first mode's period 2L/c within 1 %
    (the 40-element dispersion error is ~0.05 %), and the total energy of the
    vibration constant within 0.5 % over ten periods."""
    period, E = free_bar_mode(integration, dim, periods=10.0)
    assert period == pytest.approx(2e-3, rel=0.01)
    assert (E.max() - E.min()) / E[0] < 0.005


@pytest.mark.parametrize("integration", ["one_point", "selective_reduced"])
@pytest.mark.parametrize("dim", [2, 3])
def test_booked_internal_energy_is_the_work_of_the_element_forces(dim, integration):
    """Issue 57: one element shaped as a trapezoid (its top face half the
    bottom's, so its Gauss points stand for volumes 2.2 : 1 in 3D), random
    point stresses and node velocities, one step of 1e-12 s: the internal
    energy the part books over the step is the work of its nodal forces,
    -sum_I f_I . v_I dt, within 1e-6 (what is left is of the order of the
    step, the stress change and the geometry's move, ~1e-9). A
    selective-reduced element booked each point's work over an equal share
    of the element's volume, not over its Gauss point's: 30 % short here,
    and in the issue's crushed element (points inverted) energy from
    nothing."""
    x, cells = block([0, 0, 0], [1.0, 1.0, 1.0], (1, 1, 1), dim)
    top = x[:, dim - 1] > 0.5
    x[top, :dim - 1] = 0.25 + 0.5 * x[top, :dim - 1]
    p = part(x, cells, dim, integration=integration)
    rng = np.random.default_rng(7)
    q, pts = p.nodes, p.pts
    sig = rng.normal(0.0, 1e8, (pts.n, 3, 3))
    pts.sig[:] = 0.5 * (sig + np.swapaxes(sig, 1, 2))
    q.v[:, :dim] = rng.normal(0.0, 1.0, (q.n, dim))
    dt = 1e-12
    q.x += dt * q.v
    e0 = p.energies()[0]
    q.a[:] = 0.0
    p.internal_forces(0.0, dt)
    booked = (p.energies()[0] - e0) / dt
    power = -np.sum(q.m[:, None] * q.a * q.v)
    assert abs(power) > 1e6  # the stresses do work
    assert booked == pytest.approx(power, rel=1e-6)


def test_checkpoint_restore_continues_bitwise():
    """State, restore into a fresh part, step both: the same bits."""
    x, cells = block([0, 0, 0], [1.0, 0.1, 0.1], (10, 1, 1), 3)
    runs = []
    for form in ("stiffness",):
        a = part(x, cells, 3, hourglass=form)
        a.nodes.v[:, 1] = 0.1 * x[:, 0] ** 2
        sa = Stepper([a])
        for _ in range(20):
            sa.step()
        scalars, groups = sa.state()
        b = part(x, cells, 3, hourglass=form)
        sb = Stepper([b])
        sb.restore(scalars, {k: {n: v.copy() for n, v in g.items()} for k, g in groups.items()})
        for _ in range(20):
            sa.step()
            sb.step()
        runs.append((a, b))
    for a, b in runs:
        assert np.array_equal(a.nodes.x, b.nodes.x)
        assert np.array_equal(a.pts.sig, b.pts.sig)
        assert np.array_equal(a.el.hg, b.el.hg)


def test_gmsh_file_gives_the_same_part_as_the_generated_block(tmp_path):
    """The Gmsh 4.1 block of tests/test_mesh_geometry.py (shuffled node tags,
    rotated hex node lists) as a solid part: the same nodal masses at the same
    places as the generated block's, and 50 steps from the same initial
    velocity field end at the same positions (1e-12 of the size: only the
    summation order differs)."""
    from sphdyn.geometry.mesh_files import read_mesh
    from test_mesh_geometry import HI, LO, gmsh_model, write_msh41

    ref, _, nodes, quads, hexes = gmsh_model()
    mesh = read_mesh(write_msh41(tmp_path / "block.msh", nodes, quads, hexes), 3)
    runs = []
    for m in (ref, mesh):
        p = part(m.points.copy(), m.cells.copy(), 3)
        p.nodes.v[:, 0] = 0.1 * np.sin(7.0 * m.points[:, 2])
        s = Stepper([p])
        for _ in range(50):
            s.step()
        order = np.lexsort(m.points.T[::-1])
        runs.append((p.nodes.m[order], p.nodes.x[order]))
    assert np.allclose(runs[0][0], runs[1][0], rtol=1e-13)
    size = float(np.max(HI - LO))
    assert np.abs(runs[0][1] - runs[1][1]).max() < 1e-12 * size


@pytest.mark.parametrize("integration", ["one_point", "selective_reduced"])
def test_element_fields_and_what_walls_see_of_the_nodes(integration):
    """Cell fields: the element stress is its points' mean, von Mises of a
    uniaxial stress is its magnitude, volumes sum to the block's; the nodes
    carry what a wall needs of an item (as particles do): the volume of a
    particle of their elements' size, the same on a face, an edge and a
    corner of the block (issue 57: it was the node's share of the elements,
    an eighth of an element at a corner, so a corner met the wall later), the
    material's density and bulk modulus. Tolerances: round-off (1e-12)."""
    x, cells = block([0, 0, 0], [0.2, 0.1, 0.1], (4, 2, 2), 3)
    p = part(x, cells, 3, integration=integration)
    p.pts.sig[:, 0, 0] = -30e6
    f = p.fields()
    assert np.allclose(f["stress"]()[:, 0, 0], -30e6)
    assert np.allclose(f["von_mises"](), 30e6)
    assert f["volume"]().sum() == pytest.approx(0.002, rel=1e-12)
    assert np.allclose(p.nodes.vol0, 0.05 ** 3, rtol=1e-12)  # 50 mm cubes
    assert np.allclose(p.nodes.rho0, STEEL["density"])
    assert np.allclose(p.nodes.bulk_modulus, 210e9 / (3 * (1 - 0.6)))
    assert p.nodes.m.sum() == pytest.approx(STEEL["density"] * 0.002, rel=1e-12)


# ------------------------------------------------------- vectorised hex passes
@pytest.mark.parametrize("form,qh", [("viscous", 0.1), ("stiffness", 0.15),
                                     ("viscous", 0.0), ("viscous", 1.0)])
def test_lane_passes_give_the_bits_of_the_element_by_element_passes(form, qh):
    """The one-point hex8 passes of :mod:`.hex_lanes` (16 elements side by
    side) against the element-by-element reference passes of :mod:`.solid`, on
    a distorted block of 9 x 8 x 5 = 360 elements (two blocks of 256, the last
    group padded: 104 = 6 x 16 + 8), random node velocities, random stresses,
    some elements eroded, a stiffness-form history, and a few elements
    compressed (bulk viscosity on): every output equal bit for bit (the same
    operations in the same order, so no tolerance)."""
    from sphdyn.parts.fem import hex_lanes
    from sphdyn.parts.fem import solid as ref

    rng = np.random.default_rng(5)
    x, cells = distorted_block(3, (9, 8, 5), rng, amount=0.25)
    p = part(x, cells, 3, hourglass=form, hourglass_coefficient=qh)
    assert p.lanes is not None  # the part takes the lane passes
    q, el, pts, s = p.nodes, p.el, p.pts, p.s
    q.v = rng.normal(0.0, 5.0, q.v.shape)
    q.v[cells[:40].ravel()] += -300.0 * (x[cells[:40].ravel()] - 0.5)  # compressed
    q.x = x + 1e-3 * rng.normal(size=x.shape)
    pts.sig = rng.normal(0.0, 1e8, pts.sig.shape)
    el.hg = rng.normal(0.0, 1e3, el.hg.shape)
    el.active[[3, 200, 259, 359]] = 0
    dt, m = 1e-7, el.m
    outs = []
    for kind in ("lanes", "reference"):
        L, rho = np.full_like(pts.L, 7.0), np.full_like(pts.rho, 7.0)  # untouched if eroded
        e, e_av, hg, e_hg = pts.e.copy(), pts.e_av.copy(), el.hg.copy(), el.e_hg.copy()
        vol, dt_el, fe = np.zeros(el.n), np.zeros(el.n), np.full_like(el.fe, 7.0)
        if kind == "lanes":
            hex_lanes.hex_strain_rate(q.x, q.v, el.conn, el.active, m, dt, L, rho, p.lanes)
            hex_lanes.hex_forces(q.x, q.v, el.conn, el.active, pts.sig, L, rho, pts.c, e,
                                 e_av, p.hg_form, qh, hg, e_hg, s.q1, s.q2, dt, vol, dt_el,
                                 fe, p.lanes, q.m)
        else:
            ref.uniform_strain_rate(q.x, q.v, el.conn, el.active, m, dt, 3, p.tab, L, rho,
                                    p.work)
            ref.uniform_forces(q.x, q.v, el.conn, el.active, pts.sig, L, rho, pts.c, e, e_av,
                               3, p.tab, p.gam, p.hg_form, qh, hg, e_hg, s.q1, s.q2, dt, vol,
                               dt_el, fe, p.work, q.m)
        outs.append((L, rho, e, e_av, hg, e_hg, vol, dt_el, fe))
    for name, a, b in zip("L rho e e_av hg e_hg vol dt_el fe".split(), *outs):
        assert np.array_equal(a, b), name
    L, rho, e, e_av, hg, e_hg, vol, dt_el, fe = outs[0]
    assert np.all(L[3] == 7.0) and np.all(fe[3] == 0.0) and dt_el[3] == np.inf
    assert np.count_nonzero(e_av - pts.e_av) > 10  # bulk viscosity acted somewhere
    if qh >= 1.0:  # the hourglass control's step acts (below the element step)
        dt0 = np.zeros(el.n)
        ref.uniform_forces(q.x, q.v, el.conn, el.active, pts.sig, L, rho, pts.c, e.copy(),
                           e_av.copy(), 3, p.tab, p.gam, p.hg_form, 0.0, hg.copy(),
                           e_hg.copy(), s.q1, s.q2, dt, vol.copy(), dt0, fe.copy(), p.work, q.m)
        assert np.count_nonzero(dt_el < dt0) > 10
    if qh > 0.0:
        assert np.count_nonzero(e_hg) > 300  # hourglass work in (almost) every element
    else:
        assert not e_hg.any() and np.array_equal(hg, el.hg)


def test_simd_sqrt_is_the_ieee_square_root():
    """The LLVM intrinsic of :mod:`sphdyn.simd` gives math.sqrt's bits (both
    correctly rounded), NaN below zero, and keeps inf and signed zero."""
    from numba import njit

    from sphdyn.simd import sqrt

    @njit
    def roots(a, out):
        for i in range(a.size):
            out[i] = sqrt(a[i])

    rng = np.random.default_rng(2)
    a = np.concatenate([np.exp(rng.uniform(-700, 700, 20000)), [0.0, -0.0, np.inf, 4.0]])
    out = np.empty_like(a)
    roots(a, out)
    assert np.array_equal(out, np.array([math.sqrt(v) for v in a]))
    assert math.copysign(1.0, out[-3]) == -1.0 and out[-1] == 2.0
    neg = np.empty(1)
    roots(np.array([-1.0]), neg)
    assert np.isnan(neg[0])


def hourglass_bound_by_hand(x, gam, dim):
    """The smaller of the trace and Gershgorin's bound of the Gram matrix of
    the Flanagan-Belytschko shape vectors of one element (node coordinates
    ``x`` (nen, 3)), formed with NumPy from the volume derivatives; also the
    Gram matrix's largest eigenvalue and its trace."""
    g = np.zeros((x.shape[0], 3))
    V = volume_gradient(x - x[0], dim, volume_table(dim), g)
    h = gam @ (x - x[0]) / V  # (modes, 3)
    shape = gam - h @ g.T  # (modes, nen)
    gram = shape @ shape.T
    bound = min(np.trace(gram), np.abs(gram).sum(axis=1).max())
    return bound, np.linalg.eigvalsh(gram).max(), V, g, np.trace(gram)


def damped_oscillator_step(A, omega2):
    """The central-difference limit 2 / (A + sqrt(A^2 + omega^2)) of
    u'' + 2 A u' + omega^2 u = 0 (Belytschko, Liu & Moran 2000, sec. 6.2)."""
    return 2.0 / (A + math.sqrt(A * A + omega2))


def overlap_by_hand(x, dim):
    """The cosine of the smallest angle between the span of an element's
    b vectors (b_I = dV/dx_I / V, the stiffness's subspace) and the span of
    its shape vectors (the hourglass control's), from orthonormal bases
    (NumPy's QR and SVD), and the bound of the module docstring written out,
    sqrt(1 - 1 / (tr(G_x G_b) - (d - 1))) (0 below 1)."""
    g = np.zeros((x.shape[0], 3))
    V = volume_gradient(x - x[0], dim, volume_table(dim), g)
    gam = hourglass_vectors(dim)
    shape = gam - (gam @ (x - x[0]) / V) @ g.T  # (modes, nen)
    b = g[:, :dim] / V
    ub = np.linalg.qr(b)[0]
    uw = np.linalg.svd(shape.T, full_matrices=False)[0]
    exact = np.linalg.svd(ub.T @ uw, compute_uv=False).max()
    xc = (x - x.mean(axis=0))[:, :dim]
    mu = np.trace((xc.T @ xc) @ (b.T @ b)) - (dim - 1)
    return exact, (math.sqrt(1.0 - 1.0 / mu) if mu > 1.0 else 0.0)


def joint_step_by_hand(g, V, c, rho, m_el, lam, qh, form, dim, overlap, q2=0.06):
    """An element's step with its hourglass terms, from the formulas of the
    module docstring of sphdyn.parts.fem.solid written out here: element
    A_e = 2 q2 c / ell, w2_e = 4 c^2 / ell^2, ell = 2 / sqrt(nen sum b^2)
    (no compression); viscous a_h = qh rho c V^((d-1)/d) / 4 gives the
    damping rate A_h = a_h lam / (2 m), stiffness k_h = qh rho c^2 sum g^2 /
    (V d) the stiffness w2_h = k_h lam / m, m = m_el / nen the element's
    share of each node's mass; the step is the smaller of the damped
    oscillator limits of (A_e + c A_h, w2_e + c w2_h) and (A_h + c A_e, w2_h
    + c w2_e), c = ``overlap``. Returns it and the element's own step."""
    nen = g.shape[0]
    m = m_el / nen
    ell = 2.0 / math.sqrt(nen * np.sum((g / V) ** 2))
    A, w2 = 2 * q2 * c / ell, 4 * c * c / ell ** 2
    if form == "viscous":
        A_h, w2_h = qh * rho * c * V ** ((dim - 1) / dim) / 4 * lam / (2 * m), 0.0
    else:
        A_h, w2_h = 0.0, qh * rho * c * c * np.sum(g * g) / (V * dim) * lam / m
    joint = min(damped_oscillator_step(A + overlap * A_h, w2 + overlap * w2_h),
                damped_oscillator_step(A_h + overlap * A, w2_h + overlap * w2))
    return joint, damped_oscillator_step(A, w2)


@pytest.mark.parametrize("A, omega", [(0.0, 1.0), (1.0, 0.0), (0.3, 2.0), (5.0, 1.0),
                                      (0.06, 2.0)])
def test_the_damped_oscillator_limit_is_the_stability_edge_of_the_scheme(A, omega):
    """The velocity-lagged central difference the parts step with (v^(n+1/2) =
    v^(n-1/2) + dt (-omega^2 u^n - 2 A v^(n-1/2)), u^(n+1) = u^n + dt
    v^(n+1/2): the damping force of the viscous hourglass control and the
    linear bulk viscosity on the last half-step's velocity) has its
    amplification matrix's spectral radius <= 1 at 0.999 of
    2 / (A + sqrt(A^2 + omega^2)) and > 1 at 1.001 of it: the formula the
    element step takes (sphdyn.parts.fem.solid.element_step) is the edge,
    neither safe by a margin nor past it."""
    dt0 = damped_oscillator_step(A, omega ** 2)

    def radius(dt):
        M = np.array([[1 - dt * dt * omega ** 2, dt * (1 - 2 * A * dt)],
                      [-omega ** 2 * dt, 1 - 2 * A * dt]])
        return np.abs(np.linalg.eigvals(M)).max()

    assert radius(0.999 * dt0) <= 1.0 + 1e-12
    assert radius(1.001 * dt0) > 1.0 + 1e-4


def test_element_step_with_hourglass_terms_is_the_damped_oscillator_limit():
    """sphdyn.parts.fem.solid.element_step with the terms a_h, w2_h and the
    overlap c equals the smaller of 2 / (A + sqrt(A^2 + omega^2)) with A =
    2 Q / ell + c a_h, omega^2 = 4 c^2 / ell^2 + c w2_h and with A = a_h + c
    2 Q / ell, omega^2 = w2_h + c 4 c^2 / ell^2 (rel. 1e-14: the same formula
    rearranged), Q = q2 c + q1 ell |dkk| in compression: at overlap 1 the
    limit of the sums, at 0 the two limits taken apart; with both terms 0 its
    bits are those of ell / (Q + sqrt(Q^2 + c^2)) at any overlap."""
    from sphdyn.parts.fem.solid import element_step

    ell, c, q1, q2 = 0.01, 3000.0, 1.5, 0.06
    for dkk in (0.0, -2e4, 3e3):
        Q = q2 * c + (q1 * ell * -dkk if dkk < 0 else 0.0)
        own = ell / (Q + math.sqrt(Q * Q + c * c))
        for ov in (0.0, 0.4, 1.0):
            assert element_step(ell, c, dkk, q1, q2, 0.0, 0.0, ov) == own
        A, w2 = 2 * Q / ell, 4 * c * c / ell ** 2
        for a_h, w2_h in ((1e5, 0.0), (0.0, 3e11), (4e4, 1e10), (1e7, 0.0), (0.0, 1e15)):
            for ov in (0.0, 0.4, 1.0):
                want = min(damped_oscillator_step(A + ov * a_h, w2 + ov * w2_h),
                           damped_oscillator_step(a_h + ov * A, w2_h + ov * w2))
                got = element_step(ell, c, dkk, q1, q2, a_h, w2_h, ov)
                assert got == pytest.approx(want, rel=1e-14)
                assert got <= own
            assert element_step(ell, c, dkk, q1, q2, a_h, w2_h, 1.0) == pytest.approx(
                damped_oscillator_step(A + a_h, w2 + w2_h), rel=1e-14)
            assert element_step(ell, c, dkk, q1, q2, a_h, w2_h, 0.0) == pytest.approx(
                min(own, damped_oscillator_step(a_h, w2_h)), rel=1e-14)


@pytest.mark.parametrize("dim", [2, 3])
def test_the_overlap_bounds_the_angle_between_stiffness_and_hourglass_subspaces(dim):
    """sphdyn.parts.fem.solid.hourglass_overlap of 200 elements with randomly
    moved nodes (up to about 0.45 of their side) and 20 parallelepipeds
    (random affine maps of the unit element) against the cosine of the
    smallest principal angle between span(b) and span(gamma) computed from
    orthonormal bases (:func:`overlap_by_hand`): never below it (1e-12:
    round-off of the two routes), equal to the formula written out (1e-12);
    exact in 2D (one hourglass mode, so one angle); 0 for the parallelepipeds
    (gamma orthogonal to b there; their mu - 1, a round-off, is below
    OVERLAP_ROUNDOFF), and the formula's for an element distorted by 1e-3
    (mu - 1 far above it). The distorted ones reach 0.4 (the bound stays
    below 1)."""
    from sphdyn.parts.fem.hourglass import hourglass_overlap

    rng = np.random.default_rng(3)
    points, cells = block([0, 0, 0], [1, 1, 1], (1, 1, 1)[:dim], dim)
    x0 = points[cells[0]]
    seen = []
    for trial in range(220):
        if trial < 20:
            F = np.eye(3) + rng.normal(scale=0.3, size=(3, 3))
            if dim == 2:
                F[2, :], F[:, 2], F[2, 2] = 0.0, 0.0, 1.0
            x = x0 @ F.T
        else:
            x = x0 + rng.normal(scale=0.15, size=x0.shape)
            if dim == 2:
                x[:, 2] = 0.0
        g = np.zeros((x.shape[0], 3))
        V = volume_gradient(x - x[0], dim, volume_table(dim), g)
        if V <= 0.0:
            continue
        exact, formula = overlap_by_hand(x, dim)
        got = hourglass_overlap(x - x[0], g, V, dim)
        assert got >= exact - 1e-12
        assert got == pytest.approx(formula, rel=1e-12, abs=1e-7)
        if dim == 2:
            assert got == pytest.approx(exact, abs=1e-7)
        if trial < 20:
            assert got == 0.0  # mu - 1 is round-off: under OVERLAP_ROUNDOFF
        else:
            seen.append(exact)
    assert max(seen) > 0.4 and len(seen) > 150
    # one node moved by 1e-3 of the side: mu - 1 about 1e-6, above the
    # round-off threshold, so the overlap is the formula's (about 1e-3), not 0
    x = x0.copy()
    x[0, 0] += 1e-3
    g = np.zeros((x.shape[0], 3))
    V = volume_gradient(x - x[0], dim, volume_table(dim), g)
    exact, formula = overlap_by_hand(x, dim)
    got = hourglass_overlap(x - x[0], g, V, dim)
    assert 1e-4 < got == pytest.approx(formula, rel=1e-6) and got >= exact - 1e-12


def test_the_matrix_condition_of_the_step_is_sufficient():
    """The element step rests on this (module docstring of
    sphdyn.parts.fem.solid): the velocity-lagged central difference
    v+ = v - dt M^-1 (K u + C v), u+ = u + dt v+ is stable where
    lambda_max(M^-1 (dt C / 2 + dt^2 K / 4)) <= 1, for any symmetric K, C >= 0
    that need not commute and a diagonal M (the scalar case is the damped
    oscillator's limit). 2,000 random systems of 2-6 unknowns at 0.999 of
    the step where the condition is an equality: spectral radius of the
    amplification matrix <= 1 + 1e-9 (round-off of the eigenvalues of a
    possibly defective matrix: the rigid modes' eigenvalue 1 is double)."""
    rng = np.random.default_rng(7)
    worst = 0.0
    for _ in range(2000):
        n = int(rng.integers(2, 7))
        a = rng.normal(size=(n, n))
        K = a @ a.T * rng.uniform(0.0, 3.0)
        b = rng.normal(size=(n, int(rng.integers(1, n + 1))))
        C = b @ b.T * rng.uniform(0.0, 3.0)
        m = rng.uniform(0.2, 2.0, n)
        s = 1.0 / np.sqrt(m)

        def excess(dt):
            S = s[:, None] * (dt * C / 2 + dt * dt * K / 4) * s[None, :]
            return np.linalg.eigvalsh(S).max() - 1.0

        lo, hi = 0.0, 1.0
        while excess(hi) < 0.0:
            hi *= 2.0
        for _ in range(60):
            lo, hi = ((lo + hi) / 2, hi) if excess((lo + hi) / 2) < 0.0 else (lo, (lo + hi) / 2)
        dt = 0.999 * lo
        Av = np.eye(n) - dt * C / m[:, None]
        Au = -dt * K / m[:, None]
        G = np.block([[np.eye(n) + dt * Au, dt * Av], [Au, Av]])
        worst = max(worst, np.abs(np.linalg.eigvals(G)).max())
    assert worst <= 1.0 + 1e-9


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("form", ["viscous", "stiffness"])
def test_an_element_distorted_into_its_hourglass_shape_takes_the_joint_step(dim, form):
    """An element whose nodes are moved by 0.8 of its side along its first
    hourglass mode (x_I += 0.8 a Gamma_1I e_x, the shape a crushed element of
    the Forrestal target took), beside an undistorted one: its step is
    :func:`joint_step_by_hand` with its own mass's share m_el / nen, lambda
    the smaller of the trace and Gershgorin's bound of the shape vectors' Gram
    matrix and the overlap of :func:`overlap_by_hand`, all formed here with
    NumPy (rel. 1e-12: the same formulas, other operation order), and at
    Q_hg = 1 far below the element's own step; the same step alone as beside
    its neighbour (rel. 1e-14: the neighbour's masses do not enter). An
    undistorted cube: lambda = 2^d exactly (orthogonal base vectors), overlap
    about 0, so at Q_hg = 1 its step is the hourglass term's own and at the
    usual Q_hg = 0.1 its element step (rel. 1e-6: the overlap is the square
    root of a round-off), in both forms."""
    a, qh = 0.1, 1.0
    gam = hourglass_vectors(dim)
    x, cells = block([0, 0, 0], [a, a, a], (1, 1, 1)[:dim], dim)
    for q in (qh, 0.1):
        cube = part(x.copy(), cells, dim, hourglass=form, hourglass_coefficient=q)
        lam, eig, V, g, trace = hourglass_bound_by_hand(x[cells[0]], gam, dim)
        assert lam == 2 ** dim and eig == pytest.approx(2 ** dim, rel=1e-12)
        assert trace == 2 ** dim * gam.shape[0]  # the trace alone: 4x too high (hex)
        rho, c = cube.pts.rho[0], cube.pts.c[0]
        want, own = joint_step_by_hand(g, V, c, rho, cube.el.m[0], lam, q, form, dim, 0.0)
        assert cube.el.dt_el[0] == pytest.approx(want, rel=1e-6)
        if q == 0.1:
            assert cube.el.dt_el[0] == pytest.approx(own, rel=1e-6)
        else:
            assert want < 0.9 * own  # the hourglass term alone limits it
    # two elements side by side, the first distorted
    x, cells = block([0, 0, 0], [2 * a, a, a], (2, 1, 1)[:dim], dim)
    x[cells[0], 0] += 0.8 * a * gam[0]
    p = part(x, cells, dim, hourglass=form, hourglass_coefficient=qh)
    p._geometry(0.0)
    p._forces(1e-9)
    lam, eig, V, g, trace = hourglass_bound_by_hand(p.nodes.x[cells[0]], gam, dim)
    assert lam >= eig > 1.5 * 2 ** dim  # distorted: larger than the cube's
    exact, overlap = overlap_by_hand(p.nodes.x[cells[0]], dim)
    assert overlap >= exact - 1e-12 and exact > 0.05  # (2D: equal)
    rho, c = p.pts.rho[0], p.pts.c[0]
    want, own = joint_step_by_hand(g, V, c, rho, p.el.m[0], lam, qh, form, dim, overlap)
    assert p.el.dt_el[0] == pytest.approx(want, rel=1e-12)
    assert want < 0.5 * own
    alone = part(x[cells[0]], np.arange(2 ** dim)[None, :], dim, hourglass=form,
                 hourglass_coefficient=qh)
    assert alone.el.dt_el[0] == pytest.approx(p.el.dt_el[0], rel=1e-14)
    # the diagnosis of a step collapse names the share the hourglass terms took
    import re
    share = re.search(r"its step ([0-9.e+-]+) of what it would be without the hourglass "
                      r"control's terms \(shape vectors' Gram bound ([0-9.e+-]+), "
                      rf"{2 ** dim} undistorted; subspace overlap ([0-9.e+-]+), 0 undistorted",
                      p.describe_limit(0))
    assert float(share[1]) == pytest.approx(want / own, rel=5e-3)  # 3 digits: < 0.5 %
    assert float(share[2]) == pytest.approx(lam, rel=5e-3)
    assert float(share[3]) == pytest.approx(overlap, rel=5e-3)
    # the same step from the volumes pass (setup and restart) as from the force pass
    forces_step = p.el.dt_el.copy()
    p._element_geometry()
    assert np.array_equal(p.el.dt_el, forces_step)


def assembled_matrices(p, qh, form):
    """Stiffness K, damping C (3N, 3N) and lumped masses (3N,) of a hex8 part of
    the steel of :func:`fem_models.part` about its current shape at zero
    stress, formed here with NumPy: element stiffness V B^T D B of the
    one-point gradient b = dV/dx / V (isotropic D), hourglass damping
    a_h gamma^T gamma (viscous, a_h = Q_hg rho c V^(2/3) / 4) or stiffness
    k_h gamma^T gamma (k_h = Q_hg rho c^2 sum g^2 / (3 V)) of the shape
    vectors gamma, each component alike."""
    E, nu = 210e9, 0.3
    lame, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    D = np.zeros((6, 6))
    D[:3, :3] = lame
    D[range(6), range(6)] += [2 * mu] * 3 + [mu] * 3
    gam = hourglass_vectors(3)
    n = p.nodes.n
    K, C = np.zeros((3 * n, 3 * n)), np.zeros((3 * n, 3 * n))
    for e in range(p.el.n):
        conn = p.el.conn[e]
        xl = p.nodes.x[conn] - p.nodes.x[conn[0]]
        g = np.zeros((8, 3))
        V = volume_gradient(xl, 3, volume_table(3), g)
        b = g / V
        B = np.zeros((6, 24))
        for I in range(8):
            c0, c1, c2 = 3 * I, 3 * I + 1, 3 * I + 2
            B[0, c0], B[1, c1], B[2, c2] = b[I]
            B[3, c0], B[3, c1] = b[I, 1], b[I, 0]
            B[4, c1], B[4, c2] = b[I, 2], b[I, 1]
            B[5, c0], B[5, c2] = b[I, 2], b[I, 0]
        shape = gam - (gam @ xl / V) @ g.T
        G = np.kron(shape.T @ shape, np.eye(3))
        rho, c = p.el.m[e] / V, p.pts.c[e]
        idx = (3 * conn[:, None] + np.arange(3)).ravel()
        K[np.ix_(idx, idx)] += V * B.T @ D @ B
        if form == "viscous":
            C[np.ix_(idx, idx)] += qh * rho * c * V ** (2 / 3) / 4 * G
        else:
            K[np.ix_(idx, idx)] += qh * rho * c * c * np.sum(g * g) / (3 * V) * G
    return K, C, np.repeat(p.nodes.m, 3)


@pytest.mark.parametrize("form", ["viscous", "stiffness"])
@pytest.mark.parametrize("shape", ["spike", "checkerboard"])
def test_a_distorted_mesh_is_stable_at_its_smallest_element_step(form, shape):
    """A 4 x 4 x 2 hex block (bottom fixed) whose four top elements around the
    centre share a distorted edge: its top centre node lifted by 3 sides
    ("spike", Gram bound 14 against 8) or the 18 nodes of those elements
    moved by +-0.45 side in x in the hourglass pattern (-1)^(i+j+k)
    ("checkerboard", 13), Q_hg 0.1 and 0.3. At 0.999 of the smallest element
    step (sphdyn.parts.fem.solid.element_step with its share masses and
    overlaps) the assembled system of :func:`assembled_matrices` meets the
    matrix condition of :func:`test_the_matrix_condition_of_the_step_is_sufficient`,
    lambda_max(M^-1 (dt C / 2 + dt^2 K / 4)) <= 1 (measured 0.38-0.79: the
    element bounds' margin), and the velocity-lagged scheme's amplification
    matrix has spectral radius <= 1 + 1e-9 (modes without stiffness keep
    their displacement: eigenvalue 1)."""
    a = 0.01
    x, cells = block([0, 0, 0], [4 * a, 4 * a, 2 * a], (4, 4, 2))
    ijk = np.rint(x / a).astype(int)
    if shape == "spike":
        x[np.all(ijk == (2, 2, 2), axis=1), 2] += 3.0 * a
    else:
        patch = np.all((ijk[:, :2] >= 1) & (ijk[:, :2] <= 3), axis=1) & (ijk[:, 2] >= 1)
        x[patch, 0] += 0.45 * a * (-1.0) ** ijk[patch].sum(axis=1)
    fixed = np.repeat(ijk[:, 2] == 0, 3)
    for qh in (0.1, 0.3):
        p = part(x.copy(), cells, 3, hourglass=form, hourglass_coefficient=qh)
        K, C, m = assembled_matrices(p, qh, form)
        K, C, m = (K[np.ix_(~fixed, ~fixed)], C[np.ix_(~fixed, ~fixed)], m[~fixed])
        dt = 0.999 * p.el.dt_el.min()
        s = 1.0 / np.sqrt(m)
        cond = np.linalg.eigvalsh(s[:, None] * (dt * C / 2 + dt * dt * K / 4) * s[None, :])
        assert cond.max() <= 1.0
        n = m.size
        Av = np.eye(n) - dt * C / m[:, None]
        Au = -dt * K / m[:, None]
        amp = np.block([[np.eye(n) + dt * Au, dt * Av], [Au, Av]])
        assert np.abs(np.linalg.eigvals(amp)).max() <= 1.0 + 1e-9


def test_the_hourglass_bound_and_rates():
    """sphdyn.parts.fem.solid.hourglass_bound on shape vectors given directly
    (node coordinates at zero, so gamma = the rows passed) is the smaller of
    the trace and Gershgorin's row sums. Undistorted hex modes: trace 32,
    Gershgorin 8 (exact). Four modes a0 and three times a0/2: Gram [[1, 1/2,
    1/2, 1/2], [1/2, 1/4, ...]], trace 1.75, Gershgorin's largest row 2.5, so
    the trace is the smaller. hourglass_rates: (a_h lambda / (2 m), 0)
    viscous, (0, k_h lambda / m) stiffness, (0, 0) without control."""
    from sphdyn.parts.fem.hourglass import (HG_STIFFNESS, HG_VISCOUS, hourglass_bound,
                                            hourglass_rates)

    xl, g = np.zeros((8, 3)), np.ones((8, 3))
    gam = hourglass_vectors(3)
    assert hourglass_bound(xl, g, 1.0, gam) == 8.0
    a0 = np.zeros(8)
    a0[0] = 1.0
    skew = np.array([a0, 0.5 * a0, 0.5 * a0, 0.5 * a0])
    assert hourglass_bound(xl, g, 1.0, skew) == 1.75
    coef, m = 2.0, 3.0
    assert hourglass_rates(8.0, coef, m, HG_VISCOUS) == (pytest.approx(8.0 / 3.0, rel=1e-15),
                                                         0.0)
    assert hourglass_rates(8.0, coef, m, HG_STIFFNESS) == (0.0, pytest.approx(16.0 / 3.0,
                                                                                rel=1e-15))
    assert hourglass_rates(8.0, 0.0, m, HG_VISCOUS) == (0.0, 0.0)


@pytest.mark.parametrize("height, qh", [(1.0, 0.1), (0.1, 0.1), (0.02, 0.1), (1.0, 0.15),
                                        (1.0, 0.3)])
def test_a_crushed_warped_hex_loses_its_hourglass_mode_at_its_own_step(height, qh):
    """One concrete hex of 2 mm crushed to ``height`` of its side, one top corner
    lifted and the opposite one sheared (the elements under the penetration
    runs' projectile), started in the hourglass mode (-1)^(i+j+k) along x at
    1 m/s and stepped at its own stable step with the viscous form of
    coefficient ``qh``: the hourglass force and the stress take the mode
    down; the largest node speed never exceeds the start's and has at least
    halved after 12 steps (measured at 0.1: 0.15, 0.07, 0.37 m/s). The
    explicit viscous term multiplies the mode by |1 - k| per step, k = 8 coef
    dt / m_I = 16 Q_hg c dt / V^(1/3) = 8.3 Q_hg for a cube at the element
    step and CFL 0.9 (k = 2, the limit, at Q_hg = 0.24): at 0.15 the cube
    still loses its mode at the element step; at 0.3 the step with the
    hourglass control's damping in it (k < 2 x 0.9 at CFL 0.9) loses it too
    (it grew to 9 m/s in 12 steps at the element step, before the hourglass
    control's terms were in the step). The
    deck still takes Q_hg <= 0.15 (LS-DYNA's advice for its viscous forms)."""
    a = 2e-3
    x, cells = block([0, 0, 0], [a, a, a], (1, 1, 1), 3)
    ijk = np.rint(x / a).astype(int)  # lattice indices of the undistorted cube
    top = ijk[:, 2] == 1
    x[top, 2] = height * a
    x[top & (ijk[:, 0] == 1) & (ijk[:, 1] == 1), 2] += 0.75 * height * a
    x[top & (ijk[:, 0] == 0) & (ijk[:, 1] == 0), 0] += 0.5 * a
    s = part(x, cells, 3, mat=material(density=2400.0, E=30e9, nu=0.2),
             hourglass_coefficient=qh)
    s.nodes.v[:, 0] = (-1.0) ** ijk.sum(axis=1)
    st = Stepper([s])
    speeds = []
    for _ in range(12):
        st.step()
        speeds.append(np.abs(s.nodes.v).max())
    assert max(speeds) <= 1.0
    assert speeds[-1] < 0.5
