"""Deck section [[blast]]: an empirical air-blast load (Kingery-Bulmash)."""

from typing import Literal, Optional

from pydantic import Field

from ..units import MASS, TIME
from ..values import Position, Section, name_of, quantity, reference_to


class Blast(Section):
    """[[blast]]: the blast of a TNT charge on the exposed faces of a set
    (LS-DYNA's *LOAD_BLAST_ENHANCED; docs/theory.md "Empirical blast loads").

    The pressure on each face comes from the Kingery-Bulmash fits at its
    scaled distance R / W^(1/3) and angle of incidence; no charge, air or
    products are modelled. Faces: the exterior faces of a solid [[mesh]]
    whose nodes are all in the set, or the exposed lattice faces of the
    set's particles. The fits hold from Z = 0.0531 (free air) or 0.0674
    (surface) to 40 m/kg^(1/3): a face outside is refused. In 2D the faces
    are edges and the forces per unit thickness (N/m).
    """

    name: Optional[name_of("blast")] = Field(
        None, description="Name of the load's history columns (absent: blast, "
                          "blast_2, ...).")
    set: reference_to("set") = Field(description="The [[set]] of particles or mesh "
                                                 "nodes whose exposed faces are loaded.")
    charge: quantity(MASS, "charge mass", lo=0, lo_open=True) = Field(
        description="TNT-equivalent mass of the charge (another explosive: its "
                    "mass times its TNT equivalence).")
    point: Position = Field(description="The charge's centre.")
    burst: Literal["free_air", "surface"] = Field(
        "free_air", description="free_air: a spherical charge in the air (no ground "
                                "reflection); surface: a hemispherical charge on the "
                                "ground (the ground's reflection included).")
    time: quantity(TIME, "detonation time", lo=0) = Field(
        0.0, description="When the charge detonates.")
    turned_away: Literal["incident", "unloaded"] = Field(
        "incident", description="Faces turned away from the charge: the incident "
                                "pressure (LS-DYNA) or none (a face in its own "
                                "body's shadow).")
