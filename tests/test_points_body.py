"""Bodies of given particles (``geometry.shape = "points"``, a CSV file):
the same model as the lattice they were written from, and clear errors for
a file that is not a points file."""

from __future__ import annotations

import numpy as np
import pytest

from sphdyn.build.model import build_model
from sphdyn.checks.size import estimate_size
from sphdyn.checks.thin_members import member_extents
from sphdyn.deck import DeckError, load_deck
from sphdyn.geometry.lattice import box_lattice, read_points

HEAD = """
[run]
title = "points"
dimension = {dim}
t_end = "2 us"

[[material]]
name = "c"
model = "elastic"
density = "2400 kg/m^3"
E = "30 GPa"
nu = 0.2

[[body]]
name = "b"
material = "c"
dx = "2 mm"
velocity = [0, -1, 0]
"""


def _decks(tmp_path, dim=3):
    lo, hi = [0.0, 0.0, 0.0], [0.02, 0.01, 0.008]
    x = box_lattice(lo, hi, 0.002, dim)
    cols = "xyz"[:dim]
    # in millimetres, every digit: the file's numbers times length_unit
    np.savetxt(tmp_path / "p.csv", x[:, :dim] * 1000.0, delimiter=",",
               header=",".join(cols), comments="", fmt="%.17g")
    box = HEAD.format(dim=dim) + (
        f'geometry = {{shape = "box", lo = {lo[:dim]}, hi = {hi[:dim]}}}\n')
    pts = HEAD.format(dim=dim) + (
        'geometry = {shape = "points", file = "p.csv", length_unit = "1 mm"}\n')
    (tmp_path / "box.toml").write_text(box)
    (tmp_path / "pts.toml").write_text(pts)
    return load_deck(tmp_path / "box.toml"), load_deck(tmp_path / "pts.toml")


@pytest.mark.parametrize("dim", [2, 3])
def test_a_points_body_is_the_lattice_it_was_written_from(tmp_path, dim):
    """Positions within the roundings of x * 1000 / 1000 (the file is in mm);
    masses, volumes, smoothing lengths, materials and velocities equal."""
    box, pts = _decks(tmp_path, dim)
    a, b = build_model(box).particles, build_model(pts).particles
    # two roundings (x * 1000 written, times 0.001 read), half an ulp each
    np.testing.assert_allclose(b.x, a.x, rtol=5e-16, atol=0)
    for name in ("m", "vol0", "rho0", "h", "mat", "v", "c"):
        np.testing.assert_array_equal(getattr(b, name), getattr(a, name), err_msg=name)
    # the lattice's count estimated from its volume, the file's counted
    assert estimate_size(pts).bodies["b"] == pytest.approx(estimate_size(box).bodies["b"],
                                                           rel=1e-12)


def test_a_points_body_has_its_bounding_box_as_extents(tmp_path):
    """The thin-member check sees the particles' box, each particle dx wide:
    the lattice box's 20 x 10 x 8 mm."""
    box, pts = _decks(tmp_path)
    g, dx = pts.body[0].geometry, pts.body[0].dx
    np.testing.assert_allclose(member_extents(g, 3, dx), member_extents(box.body[0].geometry, 3),
                               rtol=1e-12)


@pytest.mark.parametrize("text, words", [
    ("a,b,c\n1,2,3\n", "no column x, y, z"),
    ("x,y,z\n1,2,oops\n", "line 2"),
    ("x,y,z\n", "a header and no particle"),
    ("", "no header line"),
])
def test_a_file_that_is_not_a_points_file(tmp_path, text, words):
    (tmp_path / "p.csv").write_text(text)
    with pytest.raises(ValueError, match=words):
        read_points(tmp_path / "p.csv", 3)
    (tmp_path / "d.toml").write_text(HEAD.format(dim=3) + 'geometry = {shape = "points", '
                                     'file = "p.csv"}\n')
    with pytest.raises(DeckError, match="geometry"):
        load_deck(tmp_path / "d.toml")
