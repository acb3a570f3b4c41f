"""Bad input ends in exit status 2 and a one-line "field + fix" message (issue 14).

Each test is a case that used to end in a traceback or in a silently wrong
answer: output paths that cannot be written, out-of-range arguments, decks
that validate but describe a model that cannot run (too large, overlapping
bodies, a body through a wall or smaller than dx, keys that mean nothing in
the deck's dimension) and the signs of the material-test summary.
"""

import csv
import json
import os
import time
from pathlib import Path

import numba
import pytest

from decks import SMALL_DISC
from sphdyn.cli import build_parser, main
from sphdyn.cli.args import _threads
from sphdyn.deck import DeckError, loads_deck
from sphdyn.build.model import build_model

EXAMPLES = Path(__file__).parent.parent / "examples"

#: Two bodies and a wall added to SMALL_DISC by the placement tests.
SECOND_BODY = """
[[body]]
name = "{name}"
material = "rubber"
dx = {dx}
geometry = {{ shape = "box", lo = [{lo}, 0.001], hi = [{hi}, 0.011] }}
"""


def _deck(tmp_path, text, name="deck.toml") -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def _small(extra: str = "", **fmt) -> str:
    return SMALL_DISC.format(t_end="1 ms", ck=0) + extra.format(**fmt)


def _exit_and_message(capsys, argv) -> tuple[int, str]:
    rc = main(argv)
    return rc, capsys.readouterr().err


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    """A run of the small disc stopped after 2 steps (frames and a checkpoint)."""
    base = tmp_path_factory.mktemp("bad_input_run")
    deck = base / "small.toml"
    deck.write_text(_small())
    out = base / "run"
    assert main(["run", str(deck), "--out", str(out), "--max-steps", "2", "-q"]) == 0
    return out


# ---------------------------------------------------------------- output paths

def test_out_under_a_regular_file_is_refused(tmp_path, capsys):
    deck = _deck(tmp_path, _small())
    (tmp_path / "file").write_text("x")
    rc, err = _exit_and_message(capsys, ["run", deck, "--out", str(tmp_path / "file" / "sub")])
    assert rc == 2 and "--out" in err and "Fix:" in err and "Traceback" not in err
    rc, err = _exit_and_message(capsys, ["run", deck, "--out", str(tmp_path / "file")])
    assert rc == 2 and "is a file" in err


@pytest.mark.skipif(hasattr(os, "geteuid") and os.geteuid() == 0,
                    reason="root ignores directory permissions")
def test_out_in_a_read_only_directory_is_refused(tmp_path, capsys):
    deck = _deck(tmp_path, _small())
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        rc, err = _exit_and_message(capsys, ["run", deck, "--out", str(locked / "out")])
        assert rc == 2 and "--out" in err and "Fix:" in err
        rc, err = _exit_and_message(capsys, ["run", deck, "--out", str(locked)])
        assert rc == 2 and "--out" in err
    finally:
        locked.chmod(0o700)


def test_export_of_a_frame_out_of_range_is_refused(run_dir, capsys):
    rc, err = _exit_and_message(capsys, ["export", str(run_dir), "--format", "csv",
                                         "--frame", "99"])
    assert rc == 2 and "--frame" in err and "frame 99" in err
    assert main(["export", str(run_dir), "--format", "csv", "--frame", "0"]) == 0


@pytest.mark.parametrize("fmt", ["vtk", "csv"])
def test_export_of_a_folder_without_frames_is_refused(tmp_path, capsys, fmt):
    """`sphdyn export DIR` of a folder with no frames (empty, or a missing
    folder) exits 2 saying so and what to do; the VTK export once wrote an
    empty particles.pvd and exited 0."""
    empty = tmp_path / "empty"
    empty.mkdir()
    rc, err = _exit_and_message(capsys, ["export", str(empty), "--format", fmt])
    assert rc == 2 and "there are no frames" in err and "Fix:" in err
    assert list(empty.iterdir()) == []
    rc, err = _exit_and_message(capsys, ["export", str(tmp_path / "nope"), "--format", fmt])
    assert rc == 2 and "no such directory" in err and "Fix:" in err


# ---------------------------------------------------------------- arguments

@pytest.mark.parametrize("argv, flag", [
    (["run", "DECK", "--threads", "0"], "--threads"),
    (["run", "DECK", "--max-steps", "-1"], "--max-steps"),
    (["restart", "DIR", "--threads", "-2"], "--threads"),
    (["bench", "rings2d", "--steps", "0"], "--steps"),
    (["material-test", "elastic", "--threads", "0"], "--threads"),
    (["ensemble", "DECK", "--samples", "0"], "--samples"),
])
def test_out_of_range_numbers_are_refused(argv, flag, capsys):
    rc, err = _exit_and_message(capsys, argv)
    assert rc == 2 and f"argument {flag}" in err and ">= " in err


@pytest.mark.parametrize("argv", [["run", "D"], ["restart", "D"], ["ensemble", "D"],
                                  ["bench", "block3d"], ["material-test", "j2"]])
def test_threads_default_is_automatic(argv):
    assert build_parser().parse_args(argv).threads is None
    before = numba.get_num_threads()
    _threads(None)
    assert numba.get_num_threads() == before


def test_version(capsys):
    from sphdyn import __version__

    assert main(["--version"]) == 0
    assert __version__ in capsys.readouterr().out


def test_restart_t_end_takes_units_and_must_be_later(run_dir, capsys):
    rc, err = _exit_and_message(capsys, ["restart", str(run_dir), "--t-end", "1 ns"])
    assert rc == 2 and "--t-end" in err and "t = " in err and "Fix:" in err
    rc, err = _exit_and_message(capsys, ["restart", str(run_dir), "--t-end", "250 kg"])
    assert rc == 2 and "--t-end" in err
    assert main(["restart", str(run_dir), "--t-end", "250 us", "--max-steps", "1",
                 "-q"]) == 0


def test_material_test_unknown_model_and_bad_param(tmp_path, capsys):
    rc, err = _exit_and_message(capsys, ["material-test", "concrete", "--path", "shear",
                                         "--out", str(tmp_path)])
    assert rc == 2 and "'concrete'" in err and "cscm" in err
    rc, err = _exit_and_message(capsys, [
        "material-test", "elastic", "--param", "density=1000", "--param", "E=-1e9",
        "--param", "nu=0.2", "--param", "colour=1", "--out", str(tmp_path)])
    assert rc == 2 and "--param E" in err and "--param colour" in err
    rc, err = _exit_and_message(capsys, ["material-test", "elastic", "--param", "E=abc"])
    assert rc == 2 and "--param E=abc" in err


ELASTIC = ["--param", "density=1000", "--param", "E=1e9", "--param", "nu=0.2",
           "--steps", "10"]


def test_triaxial_needs_a_confinement(tmp_path, capsys):
    rc, err = _exit_and_message(capsys, ["material-test", "elastic", *ELASTIC, "--path",
                                         "triaxial", "--out", str(tmp_path)])
    assert rc == 2 and "--confinement" in err
    rc, err = _exit_and_message(capsys, ["material-test", "elastic", *ELASTIC,
                                         "--confinement", "1e6", "--out", str(tmp_path)])
    assert rc == 2 and "--confinement" in err
    assert main(["material-test", "elastic", *ELASTIC, "--path", "triaxial",
                 "--confinement", "1e6", "--out", str(tmp_path)]) == 0


def test_bench_particles_only_where_honoured(capsys):
    rc, err = _exit_and_message(capsys, ["bench", "rings2d", "--particles", "1000"])
    assert rc == 2 and "--particles" in err


@pytest.mark.parametrize("path", ["hydrostatic", "shear", "uniaxial-compression"])
def test_material_test_summary_has_the_csv_signs(path, tmp_path, capsys):
    # hydrostatic used to report +pressure at +volumetric strain while the CSV
    # holds sigma_xx < 0 at eps_xx < 0
    assert main(["material-test", "elastic", *ELASTIC, "--path", path,
                 "--out", str(tmp_path)]) == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    with open(tmp_path / f"elastic_{path}.csv") as fh:
        rows = list(csv.DictReader(fh))
    stress = [float(r[summary["stress_column"]]) for r in rows]
    k = max(range(len(stress)), key=lambda i: abs(stress[i]))
    assert summary["peak_stress_Pa"] == stress[k]
    assert summary["at_strain"] == float(rows[k][summary["strain_column"]])
    if path != "shear":
        assert summary["peak_stress_Pa"] < 0 and summary["at_strain"] < 0


# ---------------------------------------------------------------- model size

def test_a_tiny_dx_is_refused_quickly_with_count_and_bytes(capsys):
    t0 = time.perf_counter()
    rc, err = _exit_and_message(capsys, ["check", str(EXAMPLES / "disc_impact.toml"),
                                         "--set", "body.0.dx=0.001 mm"])
    assert time.perf_counter() - t0 < 30
    assert rc == 2 and "body[0].dx" in err and "particles" in err and " TB" in err
    assert "run.memory_limit" in err


def test_memory_limit_is_a_deck_key(tmp_path, capsys):
    deck = _deck(tmp_path, _small().replace('[run]\n', '[run]\nmemory_limit = "100 kB"\n'))
    rc, err = _exit_and_message(capsys, ["check", deck])
    assert rc == 2 and "100 kB" in err
    rc, err = _exit_and_message(capsys, ["check", deck, "--set", "run.memory_limit=8 GHz"])
    assert rc == 2 and "run.memory_limit" in err and "GiB" in err
    assert main(["check", deck, "--set", "run.memory_limit=1 GiB"]) == 0
    out = capsys.readouterr().out
    # after the build, check reports the model's own count (the closed-form
    # estimate that the limit was checked against says 113)
    assert "estimate: about 112 particles" in out and "1.07 GB" in out


# ---------------------------------------------------------------- placement

@pytest.mark.parametrize("extra, words", [
    (SECOND_BODY.format(name="block", dx=1e-3, lo=0.004, hi=0.02), ["'disc'", "'block'",
                                                                     "overlap"]),
    (SECOND_BODY.format(name="grain", dx=0.05, lo=0.02, hi=0.03), ["'grain'", "dx"]),
    ('\n[[wall]]\nname = "roof"\npoint = [0, 0.01]\nnormal = [0, 1]\n',
     ["'disc'", "'roof'", "through"]),
    # the [domain] box: a body partly or wholly outside it, a mesh partly
    # outside (they passed check and stopped the run at its first step with
    # "enlarge [domain] if this motion is physical")
    ('\n[domain]\nlo = [-0.01, 0]\nhi = [0.01, 0.01]\n',
     ["body[0].geometry", "'disc' lies partly outside the domain box",
      "[-0.01, 0] .. [0.01, 0.01] m", "12 of its 112 particles"]),
    ('\n[domain]\nlo = [0.1, 0.1]\nhi = [0.2, 0.2]\n',
     ["body[0].geometry", "'disc' lies wholly outside", "[domain] lo/hi"]),
    ('\n[[mesh]]\nname = "pad"\nmaterial = "rubber"\n'
     'block = { lo = [0.02, 0], hi = [0.03, 0.01], divisions = [2, 2] }\n'
     '\n[domain]\nlo = [-0.01, -0.01]\nhi = [0.025, 0.02]\n',
     ["mesh[0] 'pad'", "mesh 'pad' lies partly outside", "3 of its 9 nodes",
      "up to 0.005 m outside"]),
    # a mesh resting on the wall (its lowest nodes on the plane, 5 mm elements:
    # the default contact thickness reaches 2.5 mm), or partly behind it: the
    # contact launched its nodes in the first steps (issue 57)
    ('\n[[mesh]]\nname = "pad"\nmaterial = "rubber"\n'
     'block = { lo = [0.02, 0], hi = [0.03, 0.01], divisions = [2, 2] }\n',
     ["wall[0].thickness_factor", "mesh 'pad' starts inside wall", "3 of its 9 nodes",
      "within its contact thickness", "up to 0.0025 m deep", "thickness_factor = 0"]),
    ('\n[[mesh]]\nname = "pad"\nmaterial = "rubber"\n'
     'block = { lo = [0.02, -0.004], hi = [0.03, 0.006], divisions = [2, 2] }\n',
     ["wall[0].point", "mesh 'pad' starts inside wall", "6 of its 9 nodes",
      "3 lie behind the wall's plane", "up to 0.0065 m deep"]),
])
def test_placement_that_would_die_mid_run_is_refused(extra, words, tmp_path, capsys):
    deck = _deck(tmp_path, _small() + extra)
    rc, err = _exit_and_message(capsys, ["check", deck])
    assert rc == 2 and all(w in err for w in words) and "Fix:" in err
    out = tmp_path / "never"
    rc, err = _exit_and_message(capsys, ["run", deck, "--out", str(out)])
    assert rc == 2 and not out.exists()


def test_a_mesh_on_a_wall_without_contact_thickness_or_clear_of_it_is_accepted(tmp_path,
                                                                              capsys):
    """The mesh resting on the wall is accepted with the wall's thickness_factor
    = 0 (contact at the plane), and with the default thickness when it starts
    exactly the contact thickness (half its 5 mm elements) above the plane."""
    pad = ('\n[[mesh]]\nname = "pad"\nmaterial = "rubber"\n'
           'block = {{ lo = [0.02, {y}], hi = [0.03, {top}], divisions = [2, 2] }}\n')
    on = _small() + pad.format(y=0, top=0.01)
    deck = _deck(tmp_path, on.replace("normal = [0, 1, 0]",
                                      "normal = [0, 1, 0]\nthickness_factor = 0"))
    assert _exit_and_message(capsys, ["check", deck])[0] == 0
    deck = _deck(tmp_path, _small() + pad.format(y=0.0025, top=0.0125))
    assert _exit_and_message(capsys, ["check", deck])[0] == 0


def test_touching_bodies_are_accepted():
    deck = loads_deck((EXAMPLES / "two_boxes_close.toml").read_text())
    assert build_model(deck).particles.n == 20000


@pytest.mark.parametrize("key, value", [
    ("body.0.geometry.length", '"5 mm"'),
])
def test_a_key_of_the_other_dimension_is_refused(key, value):
    with pytest.raises(DeckError, match="means nothing in a 2D deck"):
        loads_deck(_small(), overrides=[f"{key}={value}"])


def test_a_cylinder_region_length_along_z_is_refused_in_2d():
    text = _small('[[set]]\nname = "core"\nregion = {{ shape = "cylinder", centre = '
                  '[0, 0.006], radius = 0.002, length = 0.01 }}\n')
    with pytest.raises(DeckError, match="set\\[0\\].region.length"):
        loads_deck(text)
    assert loads_deck(text.replace("length = 0.01", 'axis = "x", length = 0.01'))


# ---------------------------------------------------------------- ensembles

def test_ensemble_vary_is_validated_before_anything_starts(tmp_path, capsys):
    deck = _deck(tmp_path, _small())
    out = tmp_path / "ens"
    t0 = time.perf_counter()
    rc, err = _exit_and_message(capsys, ["ensemble", deck, "--vary", "sph.bogus=1,2",
                                         "--vary", "sph.support_scale=1,-1",
                                         "--out", str(out)])
    assert time.perf_counter() - t0 < 20
    assert rc == 2 and not out.exists()
    assert "--vary sph.bogus" in err and "--vary sph.support_scale=-1" in err


def test_ensemble_unreachable_scheduler_fails_fast(tmp_path, capsys):
    deck = _deck(tmp_path, _small())
    t0 = time.perf_counter()
    rc, err = _exit_and_message(capsys, ["ensemble", deck, "--scheduler",
                                         "tcp://127.0.0.1:1", "--out",
                                         str(tmp_path / "ens"), "-q"])
    assert time.perf_counter() - t0 < 20
    assert rc == 2 and "--scheduler" in err and "Fix:" in err
