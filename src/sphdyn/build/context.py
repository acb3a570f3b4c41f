"""What the builders share while a deck becomes a stepper."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np


@dataclass
class BuildContext:
    """The deck, its model and the parts built so far.

    ``sph``: the SPH part (None without particles), set by the ``[[body]]``
    builder; ``meshes``: mesh name -> its part, set by the ``[[mesh]]``
    builder; ``parts``: every part so far, in order; ``taken``: the names given
    to conditions on sets (:meth:`unique`).
    """

    deck: Any
    model: Any
    sph: Any = None
    meshes: dict = field(default_factory=dict)
    parts: list = field(default_factory=list)
    taken: set = field(default_factory=set)

    def unique(self, name: str) -> str:
        """``name``, or ``name_2``, ``name_3``... if taken (two conditions on one
        set)."""
        out, k = name, 1
        while out in self.taken:
            k += 1
            out = f"{name}_{k}"
        self.taken.add(out)
        return out

    def target(self, set_name: str) -> tuple[Any, np.ndarray]:
        """The part and the indices (n,) of a [[set]]: a mesh's nodes or particles."""
        if set_name in self.model.mesh_sets:
            mesh, idx = self.model.mesh_sets[set_name]
            return self.meshes[mesh], idx
        return self.sph, self.model.sets[set_name]

    def body_rows(self, name: str) -> np.ndarray:
        """The SPH part's rows (k,) of the body called ``name``."""
        return np.flatnonzero(self.sph.p.body == self.model.body_names.index(name))
