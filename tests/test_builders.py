"""Deck -> stepper through the builders' registry (sphdyn.build).

The order of the built-in builders is the order the interactions act in
(a coupling after every other interaction on its particles, embedded bars
last), so it is pinned here. Then a toy package is "installed" in a temporary
folder on sys.path (a module and a minimal ``*.dist-info`` declaring entry
points in the group ``sphdyn.builders``): it brings a part kind (free point
masses, ``[[balls]]``) and an interaction (a uniform acceleration on a part,
``[field]``), each with its own deck table, and a deck uses both at once.
"""

import numpy as np
import pytest

from sphdyn import plugins
from sphdyn.build import Builder, Built, builders, register, registry
from sphdyn.deck import DeckError, deck_model, loads_deck
from sphdyn.parts import base
from sphdyn.simulation import Simulation
from decks import SMALL_DISC
from stepping import build_stepper
from toys import install_toy


def test_built_in_builders_run_in_the_order_the_forces_need():
    deck = [(b.stage, b.table) for b in builders()]
    assert deck == [
        (100, "body"), (110, "mesh"), (200, "contact"), (210, "wall"),
        (300, "boundary"), (310, "load"), (320, "blast"), (330, "body.damping"),
        (400, "mesh.*"), (500, "mesh.embed"), (600, "run.gravity"),
        (700, "mesh.erosion"), (710, "domain")]
    per_mesh = [b.table for b in builders(mesh=True)]
    assert per_mesh == ["mesh.damping", "mesh.wall", "mesh.convert", "mesh.sublayer",
                        "mesh.contact", "mesh.erosion"]


def test_a_builder_is_refused_twice_and_out_of_its_stage(monkeypatch):
    monkeypatch.setattr(registry, "REGISTRY", dict(registry.REGISTRY))
    with pytest.raises(ValueError, match="already registered"):
        register(Builder("boundary", lambda ctx: Built(), stage=300))
    with pytest.raises(ValueError, match="stage from 400 to 499"):
        register(Builder("mesh.toy", lambda ctx, mm: Built(), stage=500, mesh=True))
    with pytest.raises(ValueError, match="plain lower-case name"):
        register(Builder("toy.table", lambda ctx: Built(), stage=350, schema=object))


TOY = '''
"""A toy package: free point masses and a uniform acceleration field."""
import numpy as np
from pydantic import Field

from sphdyn.build import Builder, Built
from sphdyn.deck.values import Section
from sphdyn.parts import register_part
from toys import PointMasses, UniformField


class BallsTable(Section):
    """[[balls]]: point masses, free of each other."""

    name: str = Field(description="Part name.")
    positions: tuple[tuple[float, float, float], ...] = Field(description="[m]")
    velocity: tuple[float, float, float] = Field(description="[m/s]")
    mass: float = Field(gt=0, description="[kg] each")


class FieldTable(Section):
    """[field]: a uniform acceleration on a part."""

    part: str = Field(description="The part it acts on.")
    g: tuple[float, float, float] = Field(description="[m/s^2]")


@register_part("points")
class Balls(PointMasses):
    """The tests' point masses as a registered part kind."""


def build_balls(ctx):
    parts = []
    for b in ctx.deck.balls:
        x = np.array(b.positions, dtype=float)
        parts.append(Balls(x, np.tile(np.array(b.velocity, float), (len(x), 1)),
                           np.full(len(x), b.mass), name=b.name))
    return Built(parts=parts)


def build_field(ctx):
    f = ctx.deck.field
    if f is None:
        return Built()
    part = next(p for p in ctx.parts if p.name == f.part)
    return Built(interactions=[UniformField(part, f.g)])


BALLS = Builder("balls", build_balls, stage=120, schema=BallsTable)
FIELD = Builder("field", build_field, stage=350, schema=FieldTable, many=False)
'''

#: the small disc with the toy's tables: two balls thrown under g
BALLS = """
[[balls]]
name = "balls"
positions = [[0.012, 0.015, 0.0], [0.014, 0.02, 0.0]]
velocity = [1.0, 2.0, 0.0]
mass = 2.0

[field]
part = "balls"
g = [0.0, -9.81, 0.0]
"""


@pytest.fixture
def toy_installed(tmp_path, monkeypatch):
    """The toy package on sys.path and registries that load entry points again."""
    forget = install_toy(tmp_path, monkeypatch, "toy_builders", TOY, "sphdyn.builders",
                         {"balls": "toy_builders:BALLS", "field": "toy_builders:FIELD"})
    monkeypatch.setattr(registry, "REGISTRY", dict(registry.REGISTRY))
    monkeypatch.setattr(plugins, "LOADED", plugins.LOADED - {registry.ENTRY_POINT_GROUP})
    monkeypatch.setattr(base, "PART_KINDS", dict(base.PART_KINDS))
    yield
    forget()


def _deck(extra=""):
    return SMALL_DISC.format(t_end="1 ms", ck=0) + extra


def test_the_toy_part_and_interaction_run_from_a_deck(toy_installed, tmp_path):
    # Leapfrog is exact for a constant acceleration at any sequence of steps
    # up to round-off: x(t) = x0 + v0 t + g t^2 / 2 (1e-12 of the travel),
    # beside the disc, whose particles the toy part must leave alone.
    deck = loads_deck(_deck(BALLS))
    assert deck.balls[0].mass == 2.0 and deck.field.g == (0.0, -9.81, 0.0)
    s = build_stepper(deck)
    balls = s.part("balls")
    assert [p.name for p in s.parts] == ["sph", "balls"]
    assert [i.name for i in s.interactions][-1] == "field"
    alone = build_stepper(loads_deck(_deck()))
    for _ in range(50):
        s.step()
        alone.step()
    x0 = np.array([[0.012, 0.015, 0.0], [0.014, 0.02, 0.0]])
    exact = x0 + np.array([1.0, 2.0, 0.0]) * s.t + 0.5 * np.array([0, -9.81, 0]) * s.t ** 2
    assert np.abs(balls.kin.x - exact).max() < 1e-12 * np.abs(exact - x0).max()
    for name, arr in alone.part("sph").kin.arrays().items():
        assert np.array_equal(arr, getattr(s.part("sph").kin, name)), name


def test_the_toy_deck_runs_as_a_simulation(toy_installed, tmp_path):
    sim = Simulation.from_deck(loads_deck(_deck(BALLS)), tmp_path / "out")
    summary = sim.run(max_steps=5, progress=False)
    assert summary["steps"] == 5 and summary["status"] == "stopped"
    assert "balls" not in summary.get("meshes", {})  # it reports no mesh
    assert sim.stepper.part("balls").kin.x[0, 0] > 0.012  # it moved


def test_the_toy_tables_are_checked_like_the_decks_own(toy_installed):
    with pytest.raises(DeckError, match=r"balls\[0\]\.mass"):
        loads_deck(_deck(BALLS.replace("mass = 2.0", "mass = -2.0")))
    with pytest.raises(DeckError, match="wieght"):
        loads_deck(_deck(BALLS.replace("[field]", "[field]\nwieght = 1")))


def test_without_the_plugin_its_tables_are_unknown():
    assert "balls" not in deck_model().model_fields
    with pytest.raises(DeckError, match="balls"):
        loads_deck(_deck(BALLS))


def test_a_plugin_table_may_not_replace_the_decks_own(toy_installed, monkeypatch):
    from toy_builders import BallsTable
    register(Builder("wall", lambda ctx: Built(), stage=121, schema=BallsTable))
    with pytest.raises(ValueError, match=r"\[wall\] would replace the deck's own"):
        deck_model()
