"""Toys for the tests of what comes from outside the package: a part of free
point masses, an interaction of a uniform acceleration, and a toy package
"installed" through entry points."""

import sys
import textwrap

import numpy as np

from sphdyn.interactions import InteractionBase
from sphdyn.state import Kinematics


class PointMasses:
    """A toy part: free point masses, no internal forces (docs/architecture.md)."""

    kind = "points"

    def __init__(self, x, v, m, name="balls"):
        self.name = name
        self.kin = Kinematics(len(x), 3)
        self.kin.x, self.kin.v, self.kin.m = x, v, m

    def stable_dt(self):
        return np.inf, 0

    def start(self, dt):
        self.kin.a[:] = 0.0

    def drift(self, dt):
        self.kin.x += dt * self.kin.v

    def update_geometry(self, t, dt):
        pass

    def internal_forces(self, t, dt):
        self.kin.a[:] = 0.0

    def energies(self):
        return 0.0, 0.0

    def columns(self):
        return {}

    def fields(self):
        return {}

    def state(self):
        return {}, {}

    def restore(self, scalars, arrays):
        pass


class UniformField(InteractionBase):
    """A toy interaction: a uniform acceleration ``g`` on every item of a part."""

    name = "field"

    def __init__(self, part, g):
        self.part, self.g = part, np.asarray(g, float)
        self.kicks = 0

    def forces(self, t, dt, a_out):
        a_out += self.g

    def after_kick(self, dt_kick):
        self.kicks += 1

    def columns(self, t):
        return {"kicks": float(self.kicks)}


def install_toy(tmp_path, monkeypatch, module: str, source: str, group: str,
                entries: dict[str, str]):
    """``source`` as module ``module`` of a package installed in ``tmp_path``
    (on sys.path, with a ``*.dist-info`` declaring ``entries``, name ->
    ``module:object``, in the entry point ``group``). Returns a function that
    forgets the module again (call it when the test ends)."""
    site = tmp_path / "site"
    info = site / f"{module}-1.0.dist-info"
    info.mkdir(parents=True)
    (site / f"{module}.py").write_text(textwrap.dedent(source))
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {module}\n"
                                   "Version: 1.0\n")
    (info / "entry_points.txt").write_text(
        f"[{group}]\n" + "".join(f"{k} = {v}\n" for k, v in entries.items()))
    monkeypatch.syspath_prepend(str(site))
    return lambda: sys.modules.pop(module, None)
