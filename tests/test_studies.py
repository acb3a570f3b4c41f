"""The study scripts' decks and reference values (studies/): cheap checks, no runs."""

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from sphdyn.deck import loads_deck
from sphdyn.build.model import build_model

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "studies"))
import formulation_bending as fb  # noqa: E402


@pytest.mark.parametrize("template", ["cantilever.toml.tmpl", "rod.toml.tmpl"])
@pytest.mark.parametrize("form", fb.FORMULATIONS, ids=[f[0] for f in fb.FORMULATIONS])
def test_study_decks_build(template, form):
    label, formulation, correction = form
    deck = loads_deck(fb._deck(template, 6, formulation, correction, label, 1e-5))
    model = build_model(deck)
    x = model.particles.x0
    across = np.unique(np.floor(x[:, 1] / (fb.THICKNESS / 6))).size
    assert across == 6
    assert x[:, 0].max() < fb.LENGTH
    assert deck.sph.correction == (correction == "true")


def test_beam_references():
    """Euler-Bernoulli value, mode shape, and the Timoshenko elements: stiff in
    shear they leave only rotary inertia (a fraction of a percent at L/H = 10)."""
    f_eb = fb.euler_bernoulli_f1()
    assert f_eb == pytest.approx(854.75, rel=1e-4)
    assert fb.mode_shape(np.array([0.0, fb.LENGTH])) == pytest.approx([0.0, 1.0], abs=1e-12)
    assert fb.timoshenko_f1(shear_factor=1e6) == pytest.approx(f_eb, rel=3e-3)
    assert fb.timoshenko_f1() < fb.timoshenko_f1(shear_factor=1e6)
    assert fb.plate_wave_speed() == pytest.approx(math.sqrt(fb.E_PLANE / fb.DENSITY))


def test_zero_crossings_of_a_sine():
    t = np.linspace(0.0, 2.3, 2001)
    tz = fb.zero_crossings(t, np.sin(2 * math.pi * t))
    assert tz == pytest.approx([0.5, 1.0, 1.5, 2.0], abs=1e-5)


def test_richardson_of_the_disc_study():
    """Richardson's extrapolation recovers f0 and the order of
    f = f0 + C h^p exactly (to round-off) on uneven spacings, and refuses
    values that are not monotone or that diverge."""
    import disc_resolution as dr

    for p in (1.0, 1.5, 2.0):
        h = [1.25, 10 / 7, 5 / 3, 2.0]
        f0, order = dr.richardson(h, [7.0 - 0.4 * x**p for x in h])
        assert f0 == pytest.approx(7.0, rel=1e-9) and order == pytest.approx(p, rel=1e-6)
    assert dr.richardson([1, 2, 3], [1.0, 2.0, 1.0]) is None  # not monotone
    assert dr.richardson([1, 2, 3], [1.0, 1.1, 3.0]) is not None  # converging
    assert dr.richardson([1, 2, 3], [1.0, 3.0, 3.1]) is None  # diverging with refinement


def test_facet_of_the_disc_study():
    """The disc study's lattice facet at the point of impact (docs/examples.md,
    "Resolution study"): at the deck's 2.5 mm the lowest row holds 8
    particles per layer, a facet 8 dx = 20 mm wide, whose first contact
    pushes rho c v w t with c = sqrt((K + 4G/3)/rho) of the deck's concrete,
    v = 15 m/s and t the disc's 20 mm thickness."""
    import disc_resolution as dr
    from sphdyn.deck import load_deck

    got = dr.facet(2.5)
    mat = load_deck(dr.DECK).material[0]
    c = math.sqrt((mat.K + 4.0 * mat.G / 3.0) / mat.density)
    assert (got["facet_particles"], got["facet_mm"]) == (8, pytest.approx(20.0, rel=1e-12))
    assert got["wave_speed_ms"] == pytest.approx(c, rel=1e-12)
    assert got["facet_force_kN"] == pytest.approx(
        1e-3 * mat.density * c * 15.0 * 0.020 * 0.020, rel=1e-12)
    fine = dr.facet(1.25)  # the finest spacing: 12 particles, 15 mm (docs' table)
    assert (fine["facet_particles"], fine["facet_mm"]) == (12, pytest.approx(15.0, rel=1e-12))


def test_lozano_section_study_reads_the_static_deck(capsys):
    """studies/lozano_section.py takes the section from the static deck
    (100 x 100 mm, 42.2 MPa, two bars at 83 mm and two at 22 mm below the
    top, f0.2 575 MPa and fu 686 MPa from its hardening) and prints the
    loads in the order the theory fixes: first yield < crushing strain <
    bars at 35 per mille < the upper bound, the last below the tests'
    14.0 kN (docs/validation.md)."""
    import re

    import lozano_section

    b, h, fc, bars, steel = lozano_section.section(
        __import__("sphdyn.deck", fromlist=["load_deck"]).load_deck(lozano_section.DECK))
    assert (b, h, fc) == pytest.approx((0.1, 0.1, 42.2e6))
    assert sorted(round(d, 6) for d, _ in bars) == [0.022, 0.022, 0.083, 0.083]
    assert steel["fu"] == pytest.approx(686e6, rel=2e-3)
    lozano_section.main()
    loads = [float(x) for x in re.findall(r"P = +([0-9.]+) kN", capsys.readouterr().out)]
    assert len(loads) == 4 and loads == sorted(loads) and loads[-1] < 14.0


def test_l_specimen_sensitivity_needs_a_tag_and_names_its_runs(monkeypatch, tmp_path):
    """examples/l_specimen.py --set (a sensitivity study) refuses to run
    without --tag, so it cannot overwrite the deck's runs or its docs
    figure, and a tagged run goes to out/l_specimen_TAG_<spacing> with the
    override after the spacing."""
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "examples"))
    import l_specimen

    monkeypatch.setattr(sys, "argv", ["l_specimen.py", "--set", "run.t_end=1e-6"])
    with pytest.raises(SystemExit):
        l_specimen.main()
    seen = {}
    monkeypatch.setattr("sphdyn.simulation.run_deck",
                        lambda deck, out, sets, **kw: seen.update(out=out, sets=sets))
    out = l_specimen.run("fine", 0.00625, False, ("run.t_end=1e-6",), "probe")
    assert out.name == "l_specimen_probe_fine" and seen["out"] == out
    assert seen["sets"] == ["body.L.dx=0.00625", "run.t_end=1e-6"]


def test_punching_study_measures_the_resisting_force_and_the_contact_peak(tmp_path):
    """studies/dropweight_punching.py: a history whose kinetic energy falls by
    2 J per ms while the mid-span deflects 0.5 mm per ms is resisted by 4 kN in
    every window (exact to round-off, 1e-9); the contact's first touch and
    peak are read off the history."""
    import dropweight_punching as dp

    t = np.arange(0.0, 0.0121, 1e-4)
    ke = 485.0 - 2000.0 * t
    u = -0.5 * t
    f = np.where(t >= 2e-4, 1e3 * (1 + np.exp(-((t - 5e-4) / 1e-4) ** 2)), 0.0)
    rows = "\n".join(",".join(repr(float(v)) for v in r) for r in zip(t, ke, u, f))
    (tmp_path / "history.csv").write_text(
        "time,E_kinetic,probe_midspan_displacement_z,F_rod_contact\n" + rows + "\n")
    got = dp.resisting_force(tmp_path)
    values = [float(w.split(" ")[2]) for w in got.split(", ")]
    assert len(values) == 3 and np.allclose(values, 4.0, rtol=1e-9)
    assert dp.contact(tmp_path) == "first touch 0.200 ms, peak 2 kN at 0.500 ms"


def test_punching_study_reads_a_meshed_beam_at_its_elements(tmp_path):
    """studies/dropweight_punching.py on a frame with a mesh ``beam``: each
    element is a point at its centroid, with its cell stress (3 x 3) and
    damages and its nodes' mean displacement and velocity, so the section
    and the damaged block read elements as they read particles (exact)."""
    import dropweight_punching as dp
    from sphdyn.geometry.mesh_blocks import block_mesh
    from sphdyn.io import MeshFrame
    from sphdyn.io.hdf5 import write_frame

    mesh = block_mesh((0, 0, 0), (0.02, 0.01, 0.01), (2, 1, 1), 3)
    pts, cells = mesh.points, mesh.cells
    disp = np.column_stack([np.zeros(len(pts)), np.zeros(len(pts)), -pts[:, 0]])
    cell = {k: np.array([0.1, 0.9]) for k in ("damage", "damage_brittle", "damage_ductile")}
    cell["stress"] = np.arange(18.0).reshape(2, 9)
    write_frame(tmp_path / "frame_000000.h5", 1e-3, 10, {"position": np.zeros((0, 3))},
                meshes={"beam": MeshFrame(points=pts + disp, cells=cells, kind="hex8",
                                          point_data={"displacement": disp, "velocity": disp},
                                          cell_data=cell)})
    t, f = dp.concrete(tmp_path / "frame_000000.h5")
    assert t == 1e-3
    x0 = f["position"] - f["displacement"]
    assert np.allclose(x0, [[0.005, 0.005, 0.005], [0.015, 0.005, 0.005]], rtol=0, atol=1e-15)
    assert np.allclose(f["displacement"][:, 2], [-0.005, -0.015], rtol=0, atol=1e-15)
    assert f["stress"].shape == (2, 3, 3) and f["stress"][1, 2, 2] == 17.0
    assert f["damage_ductile"].tolist() == [0.1, 0.9] and (f["material"] == 0).all()


def test_hourglass_trace_stability_number_of_a_lone_cube():
    """studies/hourglass_trace.py's measure on one undistorted hex8 (side a,
    every node the element's only): Gram trace 32 (4 modes x 8 nodes), and
    dt times the largest eigenvalue of M^-1/2 C M^-1/2 with C = a_h
    Gamma^T Gamma and node masses m_e / 8: 64 a_h dt / m_e, a_h = Q_hg rho c
    a^2 / 4 (the hourglass base vectors are orthogonal, |Gamma_a|^2 = 8)."""
    import hourglass_trace as ht
    from fem_models import block, part

    a, dt = 0.01, 1e-7
    x, cells = block([0, 0, 0], [a, a, a], (1, 1, 1), 3)
    p = part(x, cells, 3, hourglass_coefficient=0.1)
    trace, number = ht.stability_number(p, 0, dt)
    assert trace == pytest.approx(32.0, rel=1e-12)
    coef = 0.1 * p.pts.rho[0] * p.pts.c[0] * a * a / 4.0
    assert number == pytest.approx(64.0 * coef * dt / p.el.m[0], rel=1e-12)


def test_hourglass_patch_damping_of_a_block_of_cubes():
    """studies/hourglass_patch.py's measures on a 2 x 2 x 2 block of cubes (side
    a): every element's damping a_h Gamma^T Gamma (a_h = Q_hg rho c a^2 / 4)
    has largest eigenvalue 8 a_h; with its own shares m_e / 8 of the nodes'
    masses its number is 64 a_h / m_e, and the block's checkerboard mode (every
    element in its mode Gamma_4, sharing the centre node) reaches the same
    64 a_h / m_e assembled with the nodes' whole masses, which each element's
    own whole node masses put lower (by 0.72 here): the shares bound it, the
    whole masses do not (docs/theory.md)."""
    import hourglass_patch as hp
    from fem_models import block, part

    a = 0.01
    x, cells = block([0, 0, 0], [2 * a, 2 * a, 2 * a], (2, 2, 2), 3)
    p = part(x, cells, 3, hourglass_coefficient=0.1)
    coef = 0.1 * p.pts.rho[0] * p.pts.c[0] * a * a / 4.0
    m_e = p.el.m[0]
    C = np.zeros((p.nodes.n, p.nodes.n))
    whole = []
    for e in range(p.el.n):
        Ce = hp.element_damping(p, e)
        assert hp.largest(Ce, np.ones(8)) == pytest.approx(8.0 * coef, rel=1e-12)
        assert hp.largest(Ce, np.full(8, m_e / 8)) == pytest.approx(64.0 * coef / m_e,
                                                                     rel=1e-12)
        C[np.ix_(p.el.conn[e], p.el.conn[e])] += Ce
        whole.append(hp.largest(Ce, p.nodes.m[p.el.conn[e]]))
    assembled = hp.largest(C, p.nodes.m)
    assert assembled == pytest.approx(64.0 * coef / m_e, rel=1e-12)
    assert max(whole) < 0.75 * assembled  # 0.717: the corner nodes are an eighth


def _forrestal_quick_block(faces: str):
    import forrestal_lateral_faces as flf

    root = Path(__file__).resolve().parent.parent
    text = flf.case_with_faces(
        (root / "validation" / "cases" / "forrestal1994_ogive.toml").read_text(), faces)
    return loads_deck(text.replace("divisions = [50, 50, 60]", "divisions = [20, 20, 24]"))


def test_forrestal_rollers_hold_each_lateral_face_in_its_normal_only():
    """studies/forrestal_lateral_faces.py: the case's deck with the rollers
    builds (the quick block), each of the four sets holds one lateral face's
    nodes (21 x 25 of the 20 x 20 x 24 block), held in that face's normal
    component only."""
    deck = _forrestal_quick_block("rollers")
    model = build_model(deck)
    sets = {b.set: b for b in deck.boundary}
    assert len(sets) == 4
    for name, axis in (("side_x_lo", 0), ("side_x_hi", 0), ("side_y_lo", 1), ("side_y_hi", 1)):
        mesh, nodes = model.mesh_sets[name]
        assert mesh == "target" and len(nodes) == 21 * 25, name
        assert list(sets[name].components) == ["xyz"[axis]]


def test_forrestal_non_reflecting_faces_are_the_four_sides_and_the_back():
    """The case (and --faces non_reflecting): the four lateral faces (20 x 24
    element faces each) and the back face (20 x 20) of the quick block on
    dashpots, the impact face free; --faces free takes them all off."""
    from sphdyn.build import build_stepper
    from sphdyn.interactions.non_reflecting import NonReflectingBoundary

    st = build_stepper(_forrestal_quick_block("non_reflecting"))
    nrb = {i.name: i for i in st.interactions if isinstance(i, NonReflectingBoundary)}
    assert sorted(nrb) == ["back", "side_x_hi", "side_x_lo", "side_y_hi", "side_y_lo"]
    for name, b in nrb.items():
        assert b.n_faces == (20 * 20 if name == "back" else 20 * 24), name
    x = st.part("target").kin.x
    assert np.all(x[nrb["back"].nodes, 2] == pytest.approx(-0.36, abs=1e-12))
    assert not _forrestal_quick_block("free").boundary
