"""Empirical air-blast loads: the Kingery-Bulmash fits and their load on faces.

The fits (sphdyn.interactions.kingery_bulmash, ARL-TR-1310's imperial coefficients
converted to SI) are checked against three independent things:

* Swisdak's simplified fits of the same surface-burst data (Swisdak 1994,
  *Simplified Kingery Airblast Calculations*, NSWC, DTIC ADA526744, Table 1:
  ln Y = sum c_k (ln Z)^k, Z in m/kg^(1/3), kPa, kPa ms/kg^(1/3),
  ms/kg^(1/3)), fitted to the same data in another form: the issue asks 5 %
  at three scaled distances; measured 1.7 % at worst over Z = 0.3-30;
* the metric form of the free-air fits (UN IATG 01.80 / NATO AASTP-4:
  U = -0.214362789151 + 1.35034249993 log10 Z with Z in m/kg^(1/3), kPa,
  kPa ms/kg^(1/3)): the same polynomials in other units, so they pin our unit
  conversions to round-off of their printed digits (0.1 %);
* the ideal-gas shock relations (air, gamma = 1.4): the normal reflection
  Pr = 2 Ps (7 P0 + 4 Ps) / (7 P0 + Ps) and the shock speed
  U = c0 sqrt(1 + 6 Ps / (7 P0)) = dR/dta, which the fitted data obey where
  the air behaves as an ideal gas (Z >= 2 m/kg^(1/3); closer in, real-gas
  effects raise Pr, 10 % at Z = 0.5).

Then the load: the total impulse on the faces of a particle plate and of a
hex plate equals the sum of each face's fitted impulse, the bodies' momentum
equals that impulse, and the load's work is booked as external work.
"""

import math

import numpy as np
import pytest

from sphdyn.build import build_stepper
from sphdyn.deck import DeckError, loads_deck
from sphdyn.interactions.blast import BlastLoad, face_geometry
from sphdyn.interactions.kingery_bulmash import (SURFACE, blast_parameters, decay_coefficient,
                                    face_pressure, friedlander)

from decks import STEEL
from stepping import restarted_pair

# Swisdak (1994) Table 1, surface burst: (Z_lo, Z_hi, [c0, c1, ...])
SWISDAK = {
    "Pso": [(0.2, 2.9, [7.2106, -2.1069, -0.3229, 0.1117, 0.0685]),
            (2.9, 23.8, [7.5938, -3.0523, 0.40977, 0.0261, -0.01267])],
    "Pr": [(0.06, 2.0, [9.0060, -2.6893, -0.6295, 0.1011, 0.29255, 0.13505, 0.019736]),
           (2.0, 40.0, [8.8396, -1.7330, -2.6400, 2.2930, -0.8232, 0.14247, -0.0099])],
    "is": [(0.2, 0.96, [5.5220, 1.1170, 0.6000, -0.2920, -0.0870]),
           (0.96, 2.38, [5.4650, -0.3080, -1.4640, 1.3620, -0.4320]),
           (2.38, 33.7, [5.2749, -0.4677, -0.2499, 0.0588, -0.00554])],
    "ir": [(0.06, 40.0, [6.7853, -1.3466, 0.1010, -0.01123])],
    "ta": [(0.06, 1.5, [-0.7604, 1.8058, 0.1257, -0.0437, -0.0310, -0.00669]),
           (1.5, 40.0, [-0.7137, 1.5732, 0.5561, -0.4213, 0.1054, -0.00929])],
    "t0": [(0.2, 1.02, [0.5426, 3.2299, -1.5931, -5.9667, -4.0815, -0.9149]),
           (1.02, 2.8, [0.5440, 2.7082, -9.7354, 14.3425, -9.7791, 2.8535]),
           (2.8, 40.0, [-2.4608, 7.1639, -5.6215, 2.2711, -0.44994, 0.03486])],
}
#: SI per Swisdak's unit (kPa; kPa ms/kg^(1/3) = Pa s at W = 1 kg; ms/kg^(1/3))
SWISDAK_UNIT = {"Pso": 1e3, "Pr": 1e3, "is": 1.0, "ir": 1.0, "ta": 1e-3, "t0": 1e-3}


def swisdak(name: str, z: float) -> float:
    for lo, hi, c in SWISDAK[name]:
        if lo <= z <= hi:
            u = math.log(z)
            return SWISDAK_UNIT[name] * math.exp(sum(ck * u ** k for k, ck in enumerate(c)))
    raise ValueError(z)


@pytest.mark.parametrize("z", [0.5, 2.0, 10.0])
@pytest.mark.parametrize("name", ["Pso", "Pr", "is", "ir", "ta", "t0"])
def test_surface_burst_matches_swisdaks_fits(name, z):
    # 5 % asked (issue 18); measured at most 1.7 % (is at Z = 1) over 0.3-30
    assert blast_parameters(z, 1.0, "surface")[name] == pytest.approx(swisdak(name, z),
                                                                     rel=0.05)


def _metric(coeffs, a, b, z):
    u = a + b * math.log10(z)
    return 10.0 ** sum(c * u ** k for k, c in enumerate(coeffs))


# UN IATG 01.80 (metric) free-air fits: kPa, kPa ms/kg^(1/3)
METRIC_PSO = [2.611368669, -1.69012801396, 0.00804973591951, 0.336743114941,
              -0.00516226351334, -0.0809228619888, -0.00478507266747, 0.00793030472242,
              0.0007684469735]
METRIC_PR = [3.22958031387, -2.21400538997, 0.035119031446, 0.657599992109,
             0.0141818951887, -0.243076636231, -0.0158699803158, 0.0492741184234,
             0.00227639644004, -0.00397126276058]
METRIC_IS_NEAR = [2.38830516757, -0.443749377691, 0.168825414684, 0.0348138030308,
                  -0.010435192824]
METRIC_IS_FAR = [1.55197227115, -0.40463292088, -0.0142721946082, 0.00912366316617,
                 -0.0006750681404, -0.00800863718901, 0.00314819515931, 0.00152044783382,
                 -0.0007470265899]


@pytest.mark.parametrize("z", [0.3, 2.0, 10.0])
def test_free_air_fits_in_si_match_the_metric_tables(z):
    # the same polynomials written in metric units: pins the conversions of
    # Z (ft/lb^(1/3)), psi and the W^(1/3) scaling of times and impulses
    p = blast_parameters(z, 8.0, "free_air")  # W^(1/3) = 2 kg^(1/3)
    assert p["Pso"] == pytest.approx(1e3 * _metric(METRIC_PSO, -0.214362789151,
                                                    1.35034249993, z), rel=1e-3)
    assert p["Pr"] == pytest.approx(1e3 * _metric(METRIC_PR, -0.214362789151,
                                                   1.35034249993, z), rel=1e-3)
    near = math.log10(z) < -0.101274818
    i_s = (_metric(METRIC_IS_NEAR, 2.34723921354, 3.24299066475, z) if near
           else _metric(METRIC_IS_FAR, -1.75305660315, 2.30629231803, z))
    assert p["is"] == pytest.approx(2.0 * i_s, rel=1e-3)  # kPa ms = Pa s, times W^(1/3)


@pytest.mark.parametrize("burst", ["free_air", "surface"])
@pytest.mark.parametrize("z", [2.0, 5.0, 20.0])
def test_fits_obey_the_ideal_gas_shock_relations(burst, z):
    P0, c0 = 101325.0, 340.3
    p = blast_parameters(z, 1.0, burst)
    ps = p["Pso"]
    # normal reflection of a shock in an ideal gas, gamma = 1.4; 3 %
    # (measured within 0.8 %; the fits carry the data's scatter)
    assert p["Pr"] == pytest.approx(2 * ps * (7 * P0 + 4 * ps) / (7 * P0 + ps), rel=0.03)
    # the front's speed dR/dta (central difference of the arrival-time fit)
    # against the Rankine-Hugoniot speed; 3 % (measured within 1.5 %)
    h = 1e-4 * z
    speed = 2 * h / (blast_parameters(z + h, 1.0, burst)["ta"]
                     - blast_parameters(z - h, 1.0, burst)["ta"])
    assert speed == pytest.approx(c0 * math.sqrt(1 + 6 * ps / (7 * P0)), rel=0.03)


def test_parameters_scale_with_the_cube_root_of_the_charge():
    # Hopkinson-Cranz: at one Z, pressures are the same, times and impulses
    # scale with W^(1/3)
    a, b = blast_parameters(1.5, 1.0), blast_parameters(1.5, 27.0)
    for k in ("Pso", "Pr", "decay_s", "decay_r"):
        assert b[k] == pytest.approx(a[k], rel=1e-13)
    for k in ("ta", "t0", "is", "ir"):
        assert b[k] == pytest.approx(3.0 * a[k], rel=1e-13)


@pytest.mark.parametrize("ratio", [2.0, 2.5, 5.0, 20.0])
def test_decay_coefficient_gives_the_impulse(ratio):
    # P t0 / i = ratio; the pulse's integral (Simpson, 20001 points) is i
    P, t0 = 1.0, 1.0
    A = decay_coefficient(ratio)
    tau = np.linspace(0.0, t0, 20001)
    p = np.array([friedlander(P, t0, A, s) for s in tau])
    from scipy.integrate import simpson
    assert simpson(p, x=tau) == pytest.approx(P * t0 / ratio, rel=1e-9)
    if ratio == 2.0:
        assert A == 0.0  # the triangle


def test_a_fitted_pulse_carries_its_impulse():
    # every parameter set's two pulses integrate to the fitted impulses,
    # including where the fitted t0 is too short and is lengthened to 2 i / P:
    # the free-air reflected pulse below Z ~0.066, the incident one from Z ~34
    from scipy.integrate import quad
    for burst in ("free_air", "surface"):
        for z in (0.055, 0.1, 0.3, 1.0, 3.0, 30.0, 36.0):
            p = blast_parameters(z, 1.0, burst)
            for peak, decay, i in ((p["Pso"], p["decay_s"], p["is"]),
                                   (p["Pr"], p["decay_r"], p["ir"])):
                got = quad(lambda s: friedlander(peak, p["t0"], decay, s), 0, p["t0"],
                           epsabs=0, epsrel=1e-12)[0]
                assert got == pytest.approx(i, rel=1e-8), (burst, z)


def test_angle_of_incidence_and_timing():
    p = blast_parameters(2.0, 1.0)
    par = np.array([p["Pso"], p["Pr"], p["ta"], p["t0"], p["is"], p["ir"], p["decay_s"],
                    p["decay_r"]])
    tau = p["ta"] + 0.3 * p["t0"]
    ps = p["Pso"] * 0.7 * math.exp(-0.3 * p["decay_s"])
    pr = p["Pr"] * 0.7 * math.exp(-0.3 * p["decay_r"])
    assert face_pressure(par, 1.0, tau) == pytest.approx(pr, rel=1e-14)  # head on
    assert face_pressure(par, 0.0, tau) == pytest.approx(ps, rel=1e-14)  # side on
    assert face_pressure(par, -0.6, tau) == pytest.approx(ps, rel=1e-14)  # turned away
    # cos = 0.5: Pr/4 + Ps (1 + 1/4 - 1)
    assert face_pressure(par, 0.5, tau) == pytest.approx(0.25 * pr + 0.25 * ps, rel=1e-14)
    assert face_pressure(par, 1.0, 0.999 * p["ta"]) == 0.0  # before arrival
    assert face_pressure(par, 1.0, p["ta"] + 1.001 * p["t0"]) == 0.0  # after the phase
    assert face_pressure(par, 1.0, p["ta"]) == pytest.approx(p["Pr"], rel=1e-14)


def test_mesh_face_geometry():
    # a tilted flat quadrilateral: area and normal from the diagonals
    x = np.array([[0, 0, 0], [2, 0, 0], [2, 1, 1], [0, 1, 1]], dtype=float)
    c, n, a = face_geometry(x, np.arange(4))
    assert a == pytest.approx(2 * math.sqrt(2), rel=1e-14)
    assert np.allclose(n, [0, -1 / math.sqrt(2), 1 / math.sqrt(2)], atol=1e-15)
    assert np.allclose(c, [1, 0.5, 0.5])
    c, n, a = face_geometry(x, np.array([0, 1]))  # a 2D edge: outward (t_y, -t_x)
    assert a == pytest.approx(2.0) and np.allclose(n, [0, -1, 0])


PLATES = """
[run]
dimension = 3
t_end = "2.5 ms"
{steel}[[body]]
name = "plate"
material = "steel"
dx = "10 mm"
geometry = {{ shape = "box", lo = [-0.1, -0.1, 0], hi = [0.1, 0.1, 0.02] }}
[[mesh]]
name = "block"
material = "steel"
block = {{ lo = [0.9, -0.1, 0], hi = [1.1, 0.1, 0.02], divisions = [20, 20, 2] }}
[[set]]
name = "plate"
body = "plate"
[[set]]
name = "block"
mesh = "block"
[[blast]]
name = "on_particles"
set = "plate"
charge = "1 kg"
point = [0, 0, 1.0]
[[blast]]
name = "on_mesh"
set = "block"
charge = "1 kg"
point = [1.0, 0, 1.0]
turned_away = "unloaded"
[output]
progress = false
vtk = false
"""


def _face_impulse(load, centres, normals, areas):
    """Sum over faces of the fitted impulse -A n (ir cos^2 + is (1 + cos^2 - 2 cos))."""
    total = np.zeros(3)
    for c, n, a in zip(centres, normals, areas):
        r = load.xc - c
        R = np.linalg.norm(r)
        cos = n @ r / R
        burst = "surface" if load.burst == SURFACE else "free_air"
        p = blast_parameters(R / load.w13, load.w13 ** 3, burst)
        if cos >= 0:
            i = p["ir"] * cos ** 2 + p["is"] * (1 + cos ** 2 - 2 * cos)
        else:
            i = 0.0 if load.unload_away else p["is"]
        total -= i * a * n
    return total


def test_blast_impulse_momentum_and_work_on_particles_and_mesh():
    st = build_stepper(loads_deck(PLATES.format(steel=STEEL)))
    on_p, on_m = (next(i for i in st.interactions if i.name == n)
                  for n in ("on_particles", "on_mesh"))
    # 20 x 20 x 2 particles and hexes: 400 top + 400 bottom + 160 side faces
    assert on_p.n_faces == on_m.n_faces == 960
    assert np.allclose(on_p.area, 1e-4, rtol=1e-12) and np.allclose(on_p.half, 0.005, rtol=1e-12)
    sph, mesh = st.parts
    x0 = mesh.kin.x.copy()
    geo = [face_geometry(x0, f) for f in on_m.faces]
    want_m = _face_impulse(on_m, [g[0] for g in geo], [g[1] for g in geo],
                           [g[2] for g in geo])
    want_p = _face_impulse(on_p, sph.kin.x[on_p.item] + on_p.half[:, None] * on_p.normal,
                           on_p.normal, on_p.area)
    while st.t < 2.5e-3:  # arrival ~0.5 ms, t0 ~1.8 ms at Z ~1
        st.step()
    rec = st.record()
    got_p = np.array([rec[f"on_particles_impulse_{c}"] for c in "xyz"])
    got_m = np.array([rec[f"on_mesh_impulse_{c}"] for c in "xyz"])
    # the pulse sampled at the steps (dt ~0.6 us against t0 ~1.8 ms): the
    # jump at arrival is missed by up to half a step, P dt / (2 i) ~0.3 %;
    # 1 % asked, measured 0.10 % (particles) and 0.18 % (mesh). Sideways the faces cancel (1e-6 of the vertical).
    assert got_p[2] == pytest.approx(want_p[2], rel=0.01)
    assert got_m[2] == pytest.approx(want_m[2], rel=0.01)
    assert np.abs(got_p[:2]).max() < 1e-6 * abs(got_p[2])
    # incident pressure on the particle plate's bottom pushes back up: less
    # net impulse than the mesh plate's (bottom unloaded)
    assert abs(got_p[2]) < abs(got_m[2])
    # the bodies' momentum is the load's impulse (the kick applies F dt)
    mom_p = (sph.kin.m[:, None] * sph.kin.v).sum(axis=0)
    mom_m = (mesh.kin.m[:, None] * mesh.kin.v).sum(axis=0)
    assert mom_p[2] == pytest.approx(got_p[2], rel=1e-10)
    assert mom_m[2] == pytest.approx(got_m[2], rel=1e-10)
    # the work is external work, and the balance closes with it
    assert rec["W_external"] == pytest.approx(rec["W_on_particles"] + rec["W_on_mesh"],
                                              rel=1e-12)
    assert abs(rec["E_total"]) < 1e-3 * rec["W_external"]


def test_restart_with_a_blast_load_is_bitwise():
    deck = loads_deck(PLATES.format(steel=STEEL).replace('t_end = "2.5 ms"',
                                                         't_end = "1 ms"'))
    def advance(st):
        while st.t < 6e-4:  # into the pulse
            st.step()

    st, st2 = restarted_pair(deck, advance, 20)
    assert st.record() == st2.record()
    for part, part2 in zip(st.parts, st2.parts):
        assert np.array_equal(part.kin.x, part2.kin.x)
        assert np.array_equal(part.kin.v, part2.kin.v)


def _bad(old: str, new: str) -> str:
    text = PLATES.format(steel=STEEL)
    assert old in text
    return text.replace(old, new, 1)


@pytest.mark.parametrize("old, new, match", [
    ('point = [0, 0, 1.0]', 'point = [0, 0, 0.03]', r"blast\[0\].*scaled distances"),
    ('charge = "1 kg"', 'charge = "-1 kg"', r"blast\[0\].charge"),
    ('charge = "1 kg"', 'charge = "1 m"', r"blast\[0\].charge.*mass"),
    ('turned_away = "unloaded"', 'turned_away = "none"', r"blast\[1\].turned_away"),
    ('set = "plate"\ncharge', 'set = "plates"\ncharge', r"no set named 'plates'"),
])
def test_bad_blast_input_is_refused_naming_the_field(old, new, match):
    with pytest.raises(DeckError, match=match):
        build_stepper(loads_deck(_bad(old, new)))


def test_a_blast_on_interior_particles_or_a_beam_is_refused():
    text = PLATES.format(steel=STEEL) + """
[[set]]
name = "inner"
body = "plate"
region = { shape = "box", lo = [-0.05, -0.05, -0.01], hi = [0.05, 0.05, 0.01] }
"""
    text = text.replace('set = "plate"\ncharge', 'set = "inner"\ncharge')
    # the inner set's particles lie at z = 5 mm: their bottom faces are open
    st = build_stepper(loads_deck(text))
    inner = next(i for i in st.interactions if i.name == "on_particles")
    assert np.all(inner.normal[:, 2] == -1.0) and inner.n_faces == 100
    beam = PLATES.format(steel=STEEL).replace(
        'block = { lo = [0.9, -0.1, 0], hi = [1.1, 0.1, 0.02], divisions = [20, 20, 2] }',
        'line = { start = [0.9, 0, 0], end = [1.1, 0, 0], divisions = 4 }\nelement = "beam"'
        '\nsection = { shape = "rectangle", width = "40 mm", height = "80 mm", '
        'orientation = [0, 1, 0] }')
    with pytest.raises(DeckError, match=r"blast\[1\].set.*no faces"):
        build_stepper(loads_deck(beam))


def test_blast_load_rejects_an_empty_face_set():
    class Part:  # a part whose set has no particle with mass
        class kin:
            x = np.zeros((2, 3))
            m = np.zeros(2)
            dim = 3

        class p:
            vol0 = np.ones(2)

    with pytest.raises(ValueError, match="no exposed face"):
        BlastLoad("b", Part, 1.0, (0, 0, 1), idx=np.arange(2))


#: the same two plates in plane strain: edges for faces, the mesh's blast a
#: surface burst with the incident pressure on its bottom
PLATES_2D = (PLATES.replace("dimension = 3", "dimension = 2")
             .replace("lo = [-0.1, -0.1, 0], hi = [0.1, 0.1, 0.02]",
                      "lo = [-0.1, 0], hi = [0.1, 0.02]")
             .replace("lo = [0.9, -0.1, 0], hi = [1.1, 0.1, 0.02], divisions = [20, 20, 2]",
                      "lo = [0.9, 0], hi = [1.1, 0.02], divisions = [20, 2]")
             .replace("point = [0, 0, 1.0]", "point = [0, 1.0]\nturned_away = \"unloaded\"")
             .replace('point = [1.0, 0, 1.0]\nturned_away = "unloaded"',
                      'point = [1.0, 1.0]\nburst = "surface"'))


def test_blast_in_2d_loads_edges_per_unit_thickness():
    # plane strain: particle faces of length dx, quad4 edges; each plate
    # takes the sum of its faces' fitted impulses per unit thickness (1 %):
    # the particles a free-air burst on the faces turned to it, the elements
    # a surface burst, with the incident pressure on the bottom
    st = build_stepper(loads_deck(PLATES_2D.format(steel=STEEL)))
    on_p, on_m = (next(i for i in st.interactions if i.name == n)
                  for n in ("on_particles", "on_mesh"))
    assert on_p.n_faces == on_m.n_faces == 2 * 20 + 2 * 2
    assert np.allclose(on_p.area, 0.01, rtol=1e-12)
    sph, mesh = st.parts
    geo = [face_geometry(mesh.kin.x, f) for f in on_m.faces]
    assert sum(g[2] for g in geo) == pytest.approx(2 * 0.2 + 2 * 0.02, rel=1e-12)
    want_m = _face_impulse(on_m, [g[0] for g in geo], [g[1] for g in geo],
                           [g[2] for g in geo])
    want_p = _face_impulse(on_p, sph.kin.x[on_p.item] + on_p.half[:, None] * on_p.normal,
                           on_p.normal, on_p.area)
    while st.t < 2.5e-3:
        st.step()
    rec = st.record()
    assert rec["on_particles_impulse_y"] == pytest.approx(want_p[1], rel=0.01)
    assert rec["on_mesh_impulse_y"] == pytest.approx(want_m[1], rel=0.01)


def test_faces_of_eroded_elements_and_removed_particles_are_not_loaded():
    st = build_stepper(loads_deck(PLATES.format(steel=STEEL)))
    on_p, on_m = (next(i for i in st.interactions if i.name == n)
                  for n in ("on_particles", "on_mesh"))
    sph, mesh = st.parts
    while st.t < 6e-4:  # the pulse is on
        st.step()
    conn = mesh.el.conn
    assert all(set(f) <= set(conn[e]) for f, e in zip(on_m.faces, on_m.elements))
    top = np.flatnonzero(on_m.force[:, 2] < 0.0)
    assert top.size == 400
    gone = on_m.elements[top[:3]]
    mesh.el.active[gone] = 0  # eroded
    sph.kin.active[on_p.item[0]] = 0  # left the domain
    a = np.zeros_like(mesh.kin.a)
    on_m.forces(st.t, st.dt_step, a)
    assert np.all(on_m.force[top[:3]] == 0.0) and np.all(on_m.force[top[3:], 2] < 0.0)
    on_p.forces(st.t, st.dt_step, np.zeros_like(sph.kin.a))
    shared = on_p.item == on_p.item[0]
    assert np.all(on_p.force[shared] == 0.0) and np.any(on_p.force[~shared] != 0.0)


def test_airblast_command_prints_the_parameters(capsys):
    from sphdyn.cli import main
    assert main(["airblast", "--charge", "8 kg", "--distance", "2 m", "10",
                 "--burst", "surface"]) == 0
    rows = [line.split("|")[1:-1] for line in capsys.readouterr().out.splitlines()
            if line.startswith("| ") and not line.startswith("| R")]
    for row, r in zip(rows, (2.0, 10.0)):
        p = blast_parameters(r / 2.0, 8.0, "surface")  # Z = R / 8^(1/3)
        got = [float(c) for c in row]
        assert got[1] == pytest.approx(r / 2.0, rel=1e-3)
        assert got[2] == pytest.approx(1e-3 * p["Pso"], rel=1e-3)
        assert got[3] == pytest.approx(1e-3 * p["Pr"], rel=1e-3)
        assert got[4] == pytest.approx(1e3 * p["ta"], rel=1e-3)
        assert got[6] == pytest.approx(p["is"], rel=1e-3)  # Pa s = kPa ms
    assert main(["airblast", "--charge", "75 g", "--distance", "1 mm"]) == 2
    assert "outside the fits' range" in capsys.readouterr().err
    assert main(["airblast", "--charge", "75 m", "--distance", "1 m"]) == 2


def test_particle_faces_on_a_lattice_and_at_a_crack():
    from sphdyn.interactions.blast import particle_faces
    # a 4 x 3 patch (2D, dx 1): 2 (4 + 3) = 14 exposed edges; a zero-mass
    # crack particle inside closes its neighbours' faces and takes none itself
    g = np.stack(np.meshgrid(np.arange(4.0), np.arange(3.0), indexing="ij"), -1).reshape(-1, 2)
    x = np.zeros((12, 3))
    x[:, :2] = g
    vol, m = np.ones(12), np.ones(12)
    item, normal, half, area = particle_faces(x, vol, m, np.arange(12), 2)
    assert item.size == 14 and np.all(half == 0.5) and np.all(area == 1.0)
    assert np.all(np.abs(normal).sum(axis=1) == 1.0)
    m[5] = 0.0  # (1, 2): on the top row, a crack particle
    item2, normal2, _, _ = particle_faces(x, vol, m, np.arange(12), 2)
    assert 5 not in item2 and item2.size == 13  # its own top face is gone
    assert not np.any((item2 == 4) & (normal2[:, 1] > 0.5) & (normal2[:, 0] == 0))
