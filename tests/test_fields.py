"""The output-field registry: frames, deck names and probe quantities from one table."""

import numpy as np
import pytest

from sphdyn import fields
from sphdyn.deck.sections.output import Output, Probe
from sphdyn.state import Particles


def _particles(n=4, seed=1):
    rng = np.random.default_rng(seed)
    p = Particles.allocate(n, dim=3, n_history=4)
    p.hist_names = ["plastic_strain", "kappa", "damage_brittle", "damage_ductile"]
    for name in ("x", "x0", "v"):
        getattr(p, name)[:] = rng.normal(size=(n, 3))
    for name in ("rho", "h", "e", "damage", "m"):
        getattr(p, name)[:] = rng.random(n)
    s = rng.normal(size=(n, 3, 3))
    p.sig[:] = s + s.transpose(0, 2, 1)
    p.hist[:] = rng.random((n, 4))
    return p


def test_every_field_is_described():
    for f in fields.FIELDS.values():
        assert f.shape in ("scalar", "vector", "tensor", "history", "pair")
        assert f.unit and f.description.endswith(".")
        # a field without a getter is a cell field of meshes only; "pair"
        # (a value per element end) exists on line elements only
        assert f.getter is not None or f.cells, f.name
        assert f.shape != "pair" or f.getter is None, f.name


def test_probe_values_are_the_particle_arrays():
    p = _particles()
    expect = {
        "speed": np.linalg.norm(p.v, axis=1),
        "pressure": fields.pressure(p.sig), "von_mises": fields.von_mises(p.sig),
        "density": p.rho, "damage": p.damage, "internal_energy": p.e,
        "smoothing_length": p.h, "plastic_strain": p.hist[:, 0],
        "damage_brittle": p.hist[:, 2], "damage_ductile": p.hist[:, 3],
    }
    for k, c in enumerate("xyz"):
        expect[f"velocity_{c}"] = p.v[:, k]
        expect[f"displacement_{c}"] = p.x[:, k] - p.x0[:, k]
        expect[f"position_{c}"] = p.x[:, k]
    for c, (a, b) in {"xx": (0, 0), "yy": (1, 1), "zz": (2, 2), "xy": (0, 1),
                      "yz": (1, 2), "xz": (0, 2)}.items():
        expect[f"stress_{c}"] = p.sig[:, a, b]
    assert set(expect) == set(fields.probe_quantities())
    for name, values in expect.items():
        assert np.array_equal(fields.probe_values(p, name), values), name
    assert np.array_equal(fields.probe_values(p, "kappa"), p.hist[:, 1])


def test_probe_of_a_missing_history_variable_names_it():
    p = _particles()
    p.hist_names = ["kappa", "other"]
    with pytest.raises(ValueError, match="'plastic_strain' is not available"):
        fields.probe_values(p, "plastic_strain")


def test_deck_reads_the_registry():
    probe = Probe.model_fields["quantities"].annotation
    assert set(probe.__args__[0].__args__) == set(fields.probe_quantities())
    assert Output().fields == fields.default_fields()
    # the fields in every frame may be named too (it changes nothing): decks
    # that list "mass" from before it was always written stay valid
    assert {"position", "mass"} <= set(fields.allowed_fields())
    assert not {"position", "mass"} & set(fields.default_fields())
    assert fields.default_fields()[:3] == ("velocity", "displacement", "stress")


def test_solver_fields_override_the_fallback():
    p = _particles()
    assert np.all(np.isnan(fields.FIELDS["swegle"].getter(p, {})))
    got = fields.FIELDS["phase"].getter(p, {"phase": lambda: np.arange(p.n)})
    assert np.array_equal(got, np.arange(p.n))


def test_register_field_refuses_a_taken_name():
    with pytest.raises(ValueError, match="already registered"):
        fields.register_field(fields.FIELDS["velocity"])
