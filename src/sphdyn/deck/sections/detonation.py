"""Deck section [[detonation]]: where and when high explosives are lit."""

from typing import Optional

from pydantic import Field

from ..units import TIME
from ..values import Position, Section, quantity, reference_to


class Detonation(Section):
    """[[detonation]]: a detonation point (LS-DYNA's *INITIAL_DETONATION).

    A particle of a high explosive is lit at the earliest ``time + |x -
    point| / D`` over the points that light its material (straight-line
    distance, D its material's detonation velocity). The point must lie in
    the charge (within one particle spacing of a particle of the material).
    """

    point: Position = Field(description="The detonation point.")
    time: quantity(TIME, "detonation time", lo=0) = Field(
        0.0, description="When the point detonates.")
    material: Optional[reference_to("material")] = Field(
        None, description="The high-explosive material it lights (absent: every "
                          "high explosive of the deck).")
    rotate_with: Optional[reference_to("body")] = Field(
        None, description="A body whose cylinder is tilted (geometry.tilt): the point "
                          "turns with it about the cylinder's centre (a detonator on a "
                          "tilted charge; point is given for the upright charge).")
