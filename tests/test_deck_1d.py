"""Decks in one dimension (run.dimension = 1, uniaxial strain along x)."""

from __future__ import annotations

import numpy as np
import pytest
import tomli_w

from sphdyn.deck import DeckError, loads_deck


def _load(d):
    """Validate a deck given as a dict, through its TOML text (as a file)."""
    return loads_deck(tomli_w.dumps(d))


def _deck(geometry=None, **extra):
    d = {"run": {"dimension": 1, "t_end": 1e-3},
         "material": [{"name": "air", "model": "gas", "density": 1.2, "pressure": 1e5}],
         "body": [{"name": "tube", "material": "air", "dx": 0.01,
                   "geometry": geometry or {"shape": "box", "lo": [0], "hi": [1]}}]}
    d.update(extra)
    return d


def test_one_component_vectors_and_a_segment_of_particles():
    from sphdyn.build.model import build_model
    deck = _load(_deck(geometry={"shape": "box", "lo": ["0 mm"], "hi": ["1 m"]}))
    assert deck.body[0].geometry.lo == (0.0, 0.0, 0.0)
    p = build_model(deck).particles
    assert p.n == 100 and p.dim == 1
    assert np.allclose(p.x[:, 0], (np.arange(100) + 0.5) * 0.01)
    assert np.all(p.x[:, 1:] == 0.0)
    assert np.allclose(p.m, 1.2 * 0.01)  # kg per m^2 of cross-section


@pytest.mark.parametrize("geometry,needle", [
    ({"shape": "sphere", "centre": [0.5], "radius": 0.5}, "in a 1D deck"),
    ({"shape": "box", "lo": [0, 0], "hi": [1, 1]}, "give only [x]"),
])
def test_1d_decks_refuse_other_shapes_and_off_axis_points(geometry, needle):
    with pytest.raises(DeckError, match=r"(?s)" + needle.replace("[", r"\[").replace(
            "]", r"\]")):
        _load(_deck(geometry=geometry))


def test_1d_decks_refuse_meshes_and_the_total_lagrangian_formulation():
    with pytest.raises(DeckError, match="has updated-Lagrangian bodies"):
        d = _deck()
        d["body"][0]["formulation"] = "total_lagrangian"
        _load(d)
    with pytest.raises(DeckError, match="total_lagrangian"):
        _load(_deck(sph={"formulation": "total_lagrangian"}))
