"""Material-point driver (sphdyn.materials.driver) and ``sphdyn material-test``.

Checked against closed-form elastic and J2 responses (steel-like material,
E = 200 GPa, nu = 0.3, sigma_y = 250 MPa, H = 2 GPa): linear algebra and a
Newton solve to 1e-9 K, so 1e-6 relative tolerances have wide margin.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numba
import numpy as np
import pytest

from sphdyn.cli import main
from sphdyn.materials.driver import PATHS, drive

numba.set_num_threads(1)

DECK = Path(__file__).resolve().parents[1] / "examples" / "disc_impact.toml"

E, NU, SY, H = 200e9, 0.3, 250e6, 2e9
K = E / (3 * (1 - 2 * NU))
G = E / (2 * (1 + NU))
ELASTIC = dict(density=7800.0, E=E, nu=NU)
J2 = dict(ELASTIC, yield_stress=SY, hardening_modulus=H)


def test_uniaxial_elastic():
    r = drive("elastic", ELASTIC, "uniaxial-tension", strain=1e-3, n_steps=10)
    assert r["stress"][-1, 0] == pytest.approx(E * 1e-3, rel=1e-6)
    assert r["strain"][-1, 1] == pytest.approx(-NU * 1e-3, rel=1e-6)
    assert np.max(np.abs(r["stress"][:, 1:])) < 1e-6 * E * 1e-3
    r = drive("elastic", ELASTIC, "uniaxial-compression", strain=1e-3, n_steps=10)
    assert r["y"][-1] == pytest.approx(-E * 1e-3, rel=1e-6)


def test_hydrostatic_shear_triaxial_elastic():
    r = drive("elastic", ELASTIC, "hydrostatic", strain=3e-3, n_steps=5)
    assert r["y"][-1] == pytest.approx(K * 3e-3, rel=1e-9)      # P = K eps_v
    r = drive("elastic", ELASTIC, "shear", strain=1e-3, n_steps=5)
    assert r["y"][-1] == pytest.approx(G * 1e-3, rel=1e-6)      # tau = G gamma
    assert np.max(np.abs(r["stress"][:, :3])) < 1e-6 * G * 1e-3
    r = drive("elastic", ELASTIC, "triaxial", strain=1e-3, n_steps=20, confinement=50e6)
    s = r["stress"][-1]
    assert s[1] == pytest.approx(-50e6, rel=1e-6) and s[2] == pytest.approx(-50e6, rel=1e-6)
    # deviatoric stage is uniaxial from the confined state
    assert s[0] - s[1] == pytest.approx(-E * 1e-3, rel=1e-6)


def test_uniaxial_j2_yield_and_hardening():
    r = drive("j2", J2, "uniaxial-tension", strain=5e-3, n_steps=500)
    Et = E * H / (E + H)        # uniaxial elastoplastic tangent
    assert r["y"][-1] == pytest.approx(SY + Et * (5e-3 - SY / E), rel=1e-6)


def test_cyclic_path_reverses():
    r = drive("j2", J2, "cyclic", strain=5e-3, n_steps=400)
    x = r["x"]
    assert x.min() == pytest.approx(-5e-3, rel=1e-9)
    assert np.any(np.diff(x) > 0) and np.any(np.diff(x) < 0)
    assert np.all(np.isfinite(r["stress"]))


def test_outputs_written(tmp_path):
    r = drive("j2", J2, "uniaxial-tension", strain=2e-3, n_steps=20, out=tmp_path)
    csv_path, png = r["files"]
    assert png.stat().st_size > 1000
    with open(csv_path) as fh:
        rows = list(csv.reader(fh))
    assert rows[0][0] == "t_s" and "hist_plastic_strain" in rows[0]
    assert len(rows) == 22
    assert float(rows[-1][rows[0].index("stress_xx_Pa")]) == pytest.approx(r["y"][-1])


def test_bad_input():
    with pytest.raises(ValueError, match="unknown path"):
        drive("elastic", ELASTIC, "bogus")
    with pytest.raises(KeyError):
        drive("nomodel", ELASTIC, PATHS[0])


def test_cli_material_test(tmp_path, capsys):
    rc = main(["material-test", "j2", "--param", "density=7800", "--param", "E=2e11",
               "--param", "nu=0.3", "--param", "yield_stress=2.5e8", "--path",
               "uniaxial-tension", "--strain", "1e-3", "--steps", "10", "--out",
               str(tmp_path)])
    assert rc == 0
    assert "peak_stress_Pa" in capsys.readouterr().out
    assert (tmp_path / "j2_uniaxial-tension.csv").exists()


def test_cli_material_from_deck(tmp_path, capsys):
    rc = main(["material-test", "--deck", str(DECK),
               "--material", "concrete", "--path", "uniaxial-tension", "--strain",
               "2e-4", "--steps", "40", "--out", str(tmp_path)])
    assert rc == 0
    assert (tmp_path / "cscm_uniaxial-tension.png").exists()
    assert main(["material-test", "--deck", str(DECK),
                 "--material", "nope"]) == 2


def test_cli_cscm_without_a_density_runs_as_readme_shows(tmp_path, capsys):
    """`sphdyn material-test cscm --path uniaxial-compression` runs without
    --param density (it failed for want of one): 2400 kg/m^3 is assumed and
    said on stderr. The density does not enter a strain-driven point's
    stress, so the summary equals the one with --param density=1000 exactly."""
    import json

    args = ["material-test", "cscm", "--path", "uniaxial-compression", "--steps", "20"]
    assert main(args + ["--out", str(tmp_path / "a")]) == 0
    out, err = capsys.readouterr()
    assert "2400 kg/m^3 assumed" in err
    assumed = json.loads(out)
    assert main(args + ["--param", "density=1000", "--out", str(tmp_path / "b")]) == 0
    out, err = capsys.readouterr()
    assert "assumed" not in err
    given = json.loads(out)
    assert assumed["peak_stress_Pa"] == given["peak_stress_Pa"] < 0


@pytest.mark.parametrize("argv, fix", [
    (["gas", "--param", "gamma=1.4"], "Fix: add --param density=2400."),
    (["gas", "--param", "density=1", "--param", "eos=linear_polynomial",
      "--param", "gamma=1.4"], "--param eos=ideal_gas"),
    (["high_explosive", "--param", "density=1600"], "--param preset=tnt"),
    (["cscm", "--param", "fcc=3e7"], "did you mean 'fc'?"),
])
def test_cli_material_test_fixes_are_in_its_own_syntax(argv, fix, tmp_path, capsys):
    """Every fix of a bad material-test is written as --param key=value, not
    as a deck line (it said `add density = "2400 kg/m^3"`); an unknown key
    lists the material's parameters only (no name, model or tables)."""
    assert main(["material-test", *argv, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert fix in err, err
    assert " = \"" not in err.split("Fix:", 1)[1], err
    if "did you mean" in fix:
        assert "the parameters: density, fc," in err
        assert "name," not in err and "variation" not in err
