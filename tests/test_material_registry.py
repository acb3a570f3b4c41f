"""Material models of other packages, registered through entry points.

A toy package is "installed" in a temporary folder on sys.path: a module and
a minimal ``*.dist-info`` (METADATA and entry_points.txt) declaring the
entry point ``toy`` in the group ``sphdyn.materials``. Its model owns its
deck table (key ``stiffness``), so a deck can use it at once.
"""


import numpy as np
import pytest

from sphdyn.deck import DeckError, deck_model, loads_deck
from sphdyn import plugins
from sphdyn.materials import ELASTIC, MaterialModel, registry
from sphdyn.simulation import Simulation
from toys import install_toy

TOY = '''
"""A toy material: linear elasticity from one stiffness, nu = 1/4."""
from typing import Literal

import numpy as np
from pydantic import Field

from sphdyn.deck.sections.material import MaterialSection
from sphdyn.deck.values import PositivePressure
from sphdyn.materials import MaterialModel, elastic_update


class ToyParams(MaterialSection):
    """[[material]] model = "toy": linear elasticity with nu = 1/4."""

    model: Literal["toy"] = Field(description="Constitutive model.")
    stiffness: PositivePressure = Field(description="Young's modulus.")


def pack(values):
    E = values["stiffness"]
    return np.array([values["density"], E / 1.5, E / 2.5])  # [rho, K, G]


MODEL = MaterialModel("toy", (), pack, elastic_update, schema=ToyParams)
'''

DECK = """
[run]
dimension = 2
t_end = "1 ms"
[[material]]
name = "jelly"
model = "{model}"
density = 1000.0
stiffness = "10 MPa"
[[body]]
name = "disc"
material = "jelly"
dx = 1e-3
velocity = [0, -5.0, 0]
geometry = {{ shape = "cylinder", centre = [0, 0.0062, 0], radius = 0.006 }}
[[wall]]
name = "floor"
point = [0, 0, 0]
normal = [0, 1, 0]
[output]
progress = false
fields = ["velocity", "stress"]
"""


@pytest.fixture
def toy_installed(tmp_path, monkeypatch):
    """The toy package on sys.path and a registry that loads entry points again."""
    forget = install_toy(tmp_path, monkeypatch, "toy_material", TOY, "sphdyn.materials",
                         {"toy": "toy_material:MODEL"})
    monkeypatch.setattr(registry, "REGISTRY", dict(registry.REGISTRY))
    monkeypatch.setattr(plugins, "LOADED", plugins.LOADED - {registry.ENTRY_POINT_GROUP})
    yield
    forget()


def test_entry_point_registers_the_model_lazily(toy_installed):
    assert "toy" not in registry.REGISTRY  # nothing loaded before asking
    assert "toy" in registry.available_models()
    model = registry.get_model("toy")
    assert model.schema.__name__ == "ToyParams"
    assert model.schema in registry.material_schemas()


def test_deck_with_the_toy_material_runs(toy_installed, tmp_path):
    deck = loads_deck(DECK.format(model="toy"))
    assert type(deck.material[0]).__name__ == "ToyParams"
    assert deck.material[0].stiffness == 1e7
    sim = Simulation.from_deck(deck, tmp_path / "out")
    summary = sim.run(max_steps=5, progress=False)
    assert summary["steps"] == 5 and summary["status"] == "stopped"
    p = sim.particles
    assert np.all(np.isfinite(p.sig))
    # the wave speed the toy's parameters give, set by its kernel every step
    wave = np.sqrt((1e7 / 1.5 + 4 * 1e7 / 2.5 / 3) / 1000.0)
    assert np.allclose(p.c, wave, rtol=0.01)


def test_unknown_model_lists_the_registered_ones(toy_installed):
    with pytest.raises(DeckError) as err:
        loads_deck(DECK.format(model="tyo"))
    line = str(err.value)
    assert "material[0]: model = 'tyo' is not known in material 'jelly'" in line
    assert "did you mean 'toy'?" in line
    for name in ("elastic", "j2", "cscm", "toy"):
        assert f'"{name}"' in line


def test_built_in_deck_model_is_back_without_the_plugin():
    assert "toy" not in registry.available_models()
    assert [s.__name__ for s in registry.material_schemas()][:3] == [
        "ElasticParams", "J2Params", "CscmParams"]
    with pytest.raises(DeckError, match="model = 'toy' is not known"):
        loads_deck(DECK.format(model="toy"))
    assert deck_model() is deck_model()  # built once per set of tables


def test_broken_entry_point_is_skipped_with_a_warning(toy_installed, tmp_path):
    info = tmp_path / "site" / "toy_material-1.0.dist-info" / "entry_points.txt"
    info.write_text("[sphdyn.materials]\ntoy = toy_material:MISSING\n")
    with pytest.warns(RuntimeWarning, match="'toy'.*skipped"):
        assert "toy" not in registry.available_models()


def test_schema_must_name_its_model():
    from sphdyn.materials import ElasticParams

    with pytest.raises(ValueError, match="Literal\\['other'\\]"):
        registry.register(MaterialModel("other", (), ELASTIC.pack, ELASTIC.update,
                                        schema=ElasticParams))


def test_the_built_in_models_say_what_they_allow():
    """The flags that replace material-name checks outside ``materials/``:
    only the elastic model forms beam resultants, elastic and j2 scale their
    stress with their stress parameters (a split sublayer bar), only the high
    explosive is lit by a detonation; CSCM is none of these."""
    from sphdyn.materials import get_model

    flags = {name: (get_model(name).linear_elastic, get_model(name).stress_scalable,
                    get_model(name).explosive)
             for name in ("elastic", "j2", "high_explosive", "cscm")}
    assert flags == {"elastic": (True, True, False), "j2": (False, True, False),
                     "high_explosive": (False, False, True), "cscm": (False, False, False)}


def test_the_material_test_takes_the_models_typical_density():
    """``sphdyn material-test`` without a density gives a solid its model's
    ``test_density`` (concrete 2400, steel 7850) and a fluid none: the
    explosive keeps its preset's (TNT 1630 kg/m^3), a gas must be given one."""
    from sphdyn.cli.material_test import _test_density
    from sphdyn.materials import get_model

    assert {name: get_model(name).test_density
            for name in ("elastic", "j2", "cscm", "gas", "high_explosive")} == {
        "elastic": 2400.0, "j2": 7850.0, "cscm": 2400.0, "gas": None,
        "high_explosive": None}
    assert _test_density("j2", {}) == 7850.0
    assert _test_density("j2", {"density": 7800.0}) is None  # the user's stands
    assert _test_density("high_explosive", {"preset": "tnt"}) is None
