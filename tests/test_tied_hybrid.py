"""The constraint (tied) and hybrid transition-layer SPH-FEM couplings (thesis ch. 4).

Pinned here:

* the tie map B_a of a slave with a normal offset (tied_coupling.tie_map):
  its rows sum to the identity (momentum), a rigid rotation of the face
  moves the anchor as omega x r (the offset term's sign and factor) and it
  is the derivative of the anchor position (finite differences, 1e-6);
* the tied model's books: the slaves' masses moved to the face nodes with
  the face's shape functions (total mass to 1e-12), a rigid translation's
  kinetic energy counted once (1e-12), slaves at their anchors after steps;
* the hybrid layer: one particle per integration point of the elements next
  to the converted ones (volumes sum to the elements', 1e-12), hybrid-hybrid
  pairs out of the momentum equation, hybrid particles on their elements'
  integration points after steps (1e-12);
* each coupling (penalty with ties, tied, hybrid): total linear momentum
  conserved to round-off (1e-12 of the momentum scale), a compression pulse
  from the particles into the elements reflects less than 5 % of its
  amplitude, and no energy is created at the interface;
* the hybrid layer with the total-Lagrangian kernel: hybrid pairs cut from
  the force pass (factors, hourglass factors, own-share sums, 1e-12), kept in
  the deformation gradient, and their share of L pinned against NumPy;
  momentum, pulse and restart as for the others;
* bad input: the coupling's keys, an empty interface.
"""

from __future__ import annotations

import numpy as np
import pytest

from sphdyn.build import build_stepper
from sphdyn.deck import DeckError, loads_deck
from sphdyn.geometry.convert import hybrid_points
from sphdyn.geometry.mesh_blocks import block_mesh
from sphdyn.interactions.penalty_geometry import face_shapes
from sphdyn.interactions.tied_coupling import tie_map
from sphdyn.state import BC_SLAVE

E, RHO = 30e9, 2400.0
C_BAR = np.sqrt(E / RHO)  # nu = 0: the bar wave speed is the dilatational one

#: the material of the bars (elastic, E and rho of concrete)
MATERIAL = """
[[material]]
name = "m"
model = "elastic"
density = {rho}
E = {E}
nu = {nu}
"""

BAR2D = """
[run]
dimension = 2
t_end = "1 ms"
{material}
[[mesh]]
name = "bar"
material = "m"
integration = "{integration}"
block = {{lo = [0, 0], hi = [2, 0.1], divisions = [{nx}, {ny}]}}
convert = {{region = {{shape = "box", lo = [-1, -1], hi = [1, 1]}}, coupling = "{kind}"{extra}}}
[sph]
correction = true
[output]
progress = false
"""

BAR3D = """
[run]
dimension = 3
t_end = "1 ms"
{material}
[[mesh]]
name = "bar"
material = "m"
block = {{lo = [0, 0, 0], hi = [0.8, 0.2, 0.2], divisions = [8, 2, 2]}}
convert = {{region = {{shape = "box", lo = [0.25, -1, -1], hi = [0.55, 1, 1]}}, coupling = "{kind}"{extra}}}
[output]
progress = false
"""

EXTRA = {"penalty": ", tie_factor = 1.0", "tied": "", "hybrid": ""}
#: the [sph] line of the total-Lagrangian variants (kind "hybrid_tl")
TL = '[sph]\nformulation = "total_lagrangian"\n'


def bar2d(kind: str, nx: int = 160, integration: str = "one_point"):
    """The 2D bar; kind ``hybrid_tl``: the hybrid coupling, total-Lagrangian particles."""
    name = kind.removesuffix("_tl")
    text = BAR2D.format(material=MATERIAL.format(rho=RHO, E=E, nu=0.0), kind=name,
                        extra=EXTRA[name], nx=nx, ny=nx // 20, integration=integration)
    if kind.endswith("_tl"):
        text = text.replace("[sph]\n", TL)
    return loads_deck(text)


def bar3d_text(kind: str, extra: str | None = None) -> str:
    """The 3D bar's deck; kind ``hybrid_tl`` as in :func:`bar2d`."""
    name = kind.removesuffix("_tl")
    text = BAR3D.format(material=MATERIAL.format(rho=RHO, E=E, nu=0.25), kind=name,
                        extra=EXTRA[name] if extra is None else extra)
    return text + TL if kind.endswith("_tl") else text


def bar3d(kind: str, extra: str | None = None):
    return loads_deck(bar3d_text(kind, extra))


# --------------------------------------------------------------------- tie map
def _face(dim: int):
    """A distorted face (3D quadrilateral, 2D segment) and its node array."""
    if dim == 3:
        xn = np.array([[0.0, 0.0, 0.0], [1.1, 0.1, 0.05], [1.0, 0.9, -0.1],
                       [-0.1, 1.0, 0.1]])
        return xn, np.arange(4)
    return np.array([[0.0, 0.0, 0.0], [0.9, 0.3, 0.0]]), np.arange(2)


def _anchor(xn, face, xi, eta, g):
    B = np.zeros((4, 3, 3))
    return np.array(tie_map(xn, face, xi, eta, g, B)), B


@pytest.mark.parametrize("dim", [2, 3])
def test_tie_map_rows_sum_to_identity_and_follow_a_rigid_rotation(dim):
    xn, face = _face(dim)
    xi, eta, g = 0.3, -0.4, 0.07
    x_s, B = _anchor(xn, face, xi, eta, g)
    nf = face.size
    assert np.allclose(B[:nf].sum(axis=0) - np.diag([1.0, 1.0, 1.0]), 0.0, atol=1e-14)
    # the anchor is the face point plus g n: N_a x_a + g n
    N = np.array(face_shapes(xi, eta, nf))[:nf]
    assert np.linalg.norm(x_s - N @ xn) == pytest.approx(abs(g), rel=1e-12)
    # rigid motion v = u + omega x x: the anchor moves with the body
    omega = np.array([0.0, 0.0, 2.0]) if dim == 2 else np.array([0.5, -1.0, 2.0])
    u = np.array([0.3, -0.2, 0.0 if dim == 2 else 0.1])
    vn = u + np.cross(omega, xn)
    v_s = np.einsum("aij,aj->i", B[:nf], vn)
    assert np.allclose(v_s, u + np.cross(omega, x_s), atol=1e-12)
    # without the offset term (g = 0 in B) the rotation would be missed by g omega
    assert np.linalg.norm(np.cross(omega, x_s - N @ xn)) > 0.05


@pytest.mark.parametrize("dim", [2, 3])
def test_tie_map_is_the_derivative_of_the_anchor(dim):
    xn, face = _face(dim)
    rng = np.random.default_rng(3)
    vn = rng.normal(size=xn.shape)
    if dim == 2:
        vn[:, 2] = 0.0
    x_s, B = _anchor(xn, face, -0.2, 0.6, -0.05)
    eps = 1e-6
    xp, _ = _anchor(xn + eps * vn, face, -0.2, 0.6, -0.05)
    xm, _ = _anchor(xn - eps * vn, face, -0.2, 0.6, -0.05)
    fd = (xp - xm) / (2 * eps)
    assert np.allclose(np.einsum("aij,aj->i", B[:face.size], vn), fd, atol=1e-8)


# ------------------------------------------------------------------ tied books
def test_tied_slaves_give_their_mass_to_the_face_nodes_and_move_with_them():
    deck = bar3d("tied")
    s = build_stepper(deck)
    p, q = s.part("sph").kin, s.part("bar").kin
    cpl = s.interactions[-1]
    # 3 x 2 x 2 converted elements: both end layers (4 each) are tied
    assert cpl.slaves.size == 8 and np.all(p.bc[cpl.slaves] == BC_SLAVE)
    total = RHO * 0.8 * 0.2 * 0.2
    free = p.bc != BC_SLAVE
    assert q.m.sum() + p.m[free].sum() == pytest.approx(total, rel=1e-12)
    # a rigid translation: kinetic energy of the whole bar, once
    v = np.array([1.0, -2.0, 0.5])
    q.v[:] = v
    p.v[:] = v
    assert s.kinetic_now() == pytest.approx(0.5 * total * v @ v, rel=1e-12)
    s.step()
    assert s.record()["E_kinetic"] == pytest.approx(0.5 * total * v @ v, rel=1e-12)


def test_tied_interface_is_refused_without_particles_in_reach():
    with pytest.raises(DeckError, match="tie_factor = 0"):
        bar3d("tied", ", tie_factor = 0.0")
    with pytest.raises(DeckError, match="do not belong to coupling"):
        bar3d("tied", ', alpha = 0.2')
    with pytest.raises(DeckError, match="do not belong to coupling"):
        bar3d("hybrid", ', tie_factor = 1.0')
    with pytest.raises(DeckError, match="finds no particle"):
        build_stepper(bar3d("tied", ", tie_factor = 0.1"))


# ---------------------------------------------------------------- hybrid layer
@pytest.mark.parametrize("one_point", [True, False])
def test_hybrid_points_fill_the_layer_next_to_the_converted_elements(one_point):
    m = block_mesh((0, 0, 0), (0.6, 0.2, 0.1), (6, 2, 1), 3)
    cx = m.points[m.cells].mean(axis=1)[:, 0]
    mask = (cx > 0.2) & (cx < 0.4)  # two columns of two elements
    elem, x, vol, xi = hybrid_points(m.points, m.cells, "hex8", mask, one_point)
    rest_x = m.points[m.cells[~mask]].mean(axis=1)[:, 0]
    per = 1 if one_point else 8
    # the elements at x = 0.15 and 0.45 (two rows each), in remaining numbering
    assert sorted(set(np.round(rest_x[elem], 6))) == [0.15, 0.45]
    assert elem.size == 4 * per
    assert vol.sum() == pytest.approx(4 * 0.1 * 0.1 * 0.1, rel=1e-12)
    assert xi.shape == (4 * per, 3)


def test_hybrid_particles_ride_their_elements_and_skip_each_other():
    deck = bar2d("hybrid", nx=40)
    s = build_stepper(deck)
    p, solid = s.part("sph").kin, s.part("bar")
    cpl = s.interactions[-1]
    assert cpl.rows.size == 2  # one element layer of 2 next to x = 1
    sph = s.parts[0]
    rng = np.random.default_rng(0)
    solid.kin.v[:, :2] = 0.01 * rng.normal(size=(solid.kin.n, 2))
    for _ in range(20):
        s.step()
    conn = solid.el.conn[cpl.elem]
    x_ip = np.einsum("ha,hai->hi", cpl.N, solid.kin.x[conn])
    # slaves are placed before the drift: they sit on the integration point of
    # the nodes' previous positions moved by their interpolated velocity
    assert np.allclose(p.x[cpl.rows], x_ip, atol=1e-12)
    nl = sph.nl
    for h in cpl.rows:
        for k in range(nl.offsets[h], nl.offsets[h + 1]):
            if cpl.hybrid[nl.idx[k]]:
                assert sph.F[k] == 0.0
    others = [sph.F[k] for h in cpl.rows for k in range(nl.offsets[h], nl.offsets[h + 1])
              if not cpl.hybrid[nl.idx[k]]]
    assert np.count_nonzero(others) > 0


def test_total_lagrangian_hybrid_pairs_leave_the_forces_but_not_the_gradient():
    # The hybrid layer with the total-Lagrangian kernel: the fixed pairs of two
    # hybrid particles are cut from the force pass once (factor and hourglass
    # factor zero, the own-share sum gsum without them, to 1e-12), the
    # deformation gradient keeps them, and L^hh (the part of L they give, whose
    # stress work the coupling takes off) is [sum_hybrid V_j fac (v_j - v_i) x
    # (X_i - X_j)] B^T F^-1: pinned against a NumPy sum after steps with random
    # velocities, together with the whole L of the scheme from all pairs (the
    # same convention: sign, transpose and factor).
    s = build_stepper(loads_deck(bar3d_text("hybrid") + TL))
    sph = s.parts[0]
    t, cpl, p = sph.tl, s.interactions[-1], s.part("sph").kin
    assert cpl.tl and cpl.rows.size == 8  # one layer of 2 x 2 elements, 2 sides
    rows = np.repeat(np.arange(t.offsets.size - 1), np.diff(t.offsets))
    cut = cpl.hybrid[rows] & cpl.hybrid[t.idx]
    assert cut.any() and (t.fac[cut] != 0).any()
    assert np.all(t.fac_f[cut] == 0) and np.all(t.hgk[cut] == 0)
    assert np.array_equal(t.fac_f[~cut], t.fac[~cut])
    g = (t.vol[t.idx] * t.fac_f.astype(float))[:, None] * (t.X[rows] - t.X[t.idx])
    gsum = np.zeros_like(t.gsum)
    np.add.at(gsum, rows, g)
    assert np.allclose(t.gsum_f[t.rows], gsum[t.rows], rtol=0, atol=1e-12 * np.abs(gsum).max())
    rng = np.random.default_rng(3)
    for part in s.parts:
        part.kin.v[:] = 0.01 * rng.normal(size=part.kin.v.shape)
    for _ in range(5):
        s.step()
    for k, i in enumerate(cpl.rows):
        j = t.idx[t.offsets[i]:t.offsets[i + 1]]
        f = t.vol[j] * t.fac[t.offsets[i]:t.offsets[i + 1]].astype(float)
        raw = (f[:, None, None] * (p.v[j] - p.v[i])[:, :, None]
               * (t.X[i] - t.X[j])[:, None, :])
        corr = t.B0[i].T @ t.Finv[i]
        lhh = raw[cpl.hybrid[j]].sum(axis=0) @ corr
        assert np.allclose(cpl.Lhh[k], lhh, rtol=0, atol=1e-10 * np.abs(lhh).max())
        assert np.allclose(p.L[i], raw.sum(axis=0) @ corr, rtol=0,
                           atol=1e-10 * np.abs(p.L[i]).max())


# ------------------------------------------------------------ every coupling
def _momentum(s):
    """Total linear momentum (3,) of the free items (slaves ride on their masters)."""
    out = np.zeros(3)
    for part in s.parts:
        q = part.kin
        keep = q.bc != BC_SLAVE
        out += (q.m[keep, None] * q.v[keep]).sum(axis=0)
    return out


@pytest.mark.parametrize("kind", ["penalty", "tied", "hybrid", "hybrid_tl"])
def test_coupling_conserves_momentum_to_round_off(kind):
    s = build_stepper(bar3d(kind))
    rng = np.random.default_rng(1)
    for part in s.parts:
        part.kin.v[:] = rng.normal(size=part.kin.v.shape)
    for inter in s.interactions:
        inter.constrain(0.0, 0.0)  # slaves consistent with their masters
    p0 = _momentum(s)
    scale = sum(float(np.sum(part.kin.m * np.linalg.norm(part.kin.v, axis=1)))
                for part in s.parts)
    for _ in range(100):
        s.step()
    assert np.abs(_momentum(s) - p0).max() < 1e-12 * scale


@pytest.mark.parametrize("kind", ["penalty", "tied", "hybrid", "hybrid_tl"])
def test_compression_pulse_passes_from_particles_into_elements(kind):
    # A 2 m plane-strain bar (nu = 0: uniaxial waves at c = sqrt(E/rho)), 320 x 16
    # quadrilaterals of 6.25 mm; its left half is particles. A sin^2 velocity
    # pulse of 0.3 m (48 particles) starts in the particles; its right-going
    # half (amplitude v0/2) crosses the interface at x = 1. When it is at
    # 1.15-1.45 m (c t = 0.7 m) the particles between 0.5 and 0.9 m hold only
    # what the interface reflected (the left-going half is at x < 0.25).
    # Reflection: the largest column-mean velocity there over v0/2, < 5 % (the
    # issue's bound; measured 2.6 % tied, SPH ringing included). The
    # transmitted pulse keeps > 85 % of its amplitude (the particles'
    # artificial viscosity takes some on the way). Energy: the total at the
    # end is the initial kinetic energy, none created (< 0.1 %).
    s = build_stepper(bar2d(kind, nx=320))
    p, q = s.part("sph").kin, s.part("bar").kin
    free = p.bc != BC_SLAVE
    v0, lam, x0 = 1.0, 0.3, 0.45
    z = (p.x[free, 0] - x0) / lam
    p.v[free, 0] = np.where((z > 0) & (z < 1), v0 * np.sin(np.pi * z) ** 2, 0.0)
    ke0 = 0.5 * float(np.sum(p.m[free] * p.v[free, 0] ** 2))
    t_end = 0.7 / C_BAR
    while s.t < t_end:
        s.step(t_stop=t_end)
    xs, vx = p.x[free, 0], p.v[free, 0]
    cols = np.round(xs / (2 / 320)).astype(int)
    win = (xs > 0.5) & (xs < 0.9)
    reflected = max(abs(vx[cols == c].mean()) for c in np.unique(cols[win]))
    assert reflected < 0.05 * v0 / 2
    ahead = (q.x[:, 0] > 1.05) & (q.x[:, 0] < 1.6)
    assert q.v[ahead, 0].max() > 0.85 * v0 / 2
    # the total-Lagrangian scheme's own balance errs by +0.13 % in this pulse
    # (the tied coupling with it: the same +0.13 %, hybrid_tl - tied_tl 5e-6),
    # the Eulerian one by +0.06 %: the bound is on what the interface adds
    e_total = s.record(kinetic=s.kinetic_now())["E_total"]
    assert e_total < ke0 * (1 + (2e-3 if kind.endswith("_tl") else 1e-3))
    assert e_total == pytest.approx(ke0, rel=0.01)


PULL = """
[[set]]
name = "left"
mesh = "bar"
region = {shape = "box", lo = [-0.001, -1, -1], hi = [0.001, 1, 1]}
[[set]]
name = "right"
mesh = "bar"
region = {shape = "box", lo = [0.799, -1, -1], hi = [0.801, 1, 1]}
[[boundary]]
set = "left"
type = "fixed"
[[boundary]]
set = "right"
type = "velocity"
velocity = [0, "-2 m/s", 0]
"""


@pytest.mark.parametrize("kind", ["tied", "hybrid", "hybrid_tl"])
def test_restart_of_a_coupled_run_is_bitwise(kind, tmp_path):
    from sphdyn.cli import main
    from sphdyn.io import read_history_csv
    from sphdyn.simulation import Simulation

    text = bar3d_text(kind).replace(
        "progress = false", 'progress = false\nevery = "0.5 ms"\nhistory_every = 1') + PULL
    Simulation.from_deck(loads_deck(text), tmp_path / "full").run()
    part = Simulation.from_deck(loads_deck(text.replace(
        "history_every = 1", "history_every = 1\ncheckpoint_every = 20")), tmp_path / "part")
    part.run(max_steps=50)
    assert main(["restart", str(tmp_path / "part"), "-q"]) == 0
    h_full = read_history_csv(tmp_path / "full/history.csv")
    h_part = read_history_csv(tmp_path / "part/history.csv")
    assert h_full["right_reaction_y"].size > 60
    for col in ("right_reaction_y", "E_total", "F_bar_coupling_y"):
        assert np.array_equal(h_full[col], h_part[col]), col
    assert abs(h_full["right_reaction_y"][-1]) > 0


def test_converted_region_without_coupling_is_damped_as_a_whole():
    # coupling = "none" with mesh damping: every converted particle gets the
    # mesh's mass damping (no slaves to leave out), and the model steps
    text = bar3d_text("tied").replace('coupling = "tied"', 'coupling = "none"').replace(
        'material = "m"\n', 'material = "m"\ndamping = "100 1/s"\n', 1)
    s = build_stepper(loads_deck(text))
    names = [type(i).__name__ for i in s.interactions]
    assert "TiedCoupling" not in names
    damp = [i for i in s.interactions if getattr(i, "name", "") == "bar_particles"]
    assert len(damp) == 1 and damp[0].idx.size == s.part("sph").kin.n
    for _ in range(3):
        s.step()
