"""The consistent unit systems of keyword decks.

LS-DYNA has no units: a deck's numbers are in whatever consistent system
its author chose, which the user states (``sphdyn import --units``). A
system is its length, time and mass units; every other unit follows from
them (force = mass length / time^2, pressure = force / length^2, ...).
"""

from __future__ import annotations

from dataclasses import dataclass

#: name -> (length [m], time [s], mass [kg]) of one unit, and what the
#: system's force and stress units are called, for the help text
SYSTEMS: dict[str, tuple[float, float, float, str]] = {
    "m-s-kg": (1.0, 1.0, 1.0, "N, Pa"),
    "mm-ms-kg": (1e-3, 1e-3, 1.0, "kN, GPa"),
    "mm-s-t": (1e-3, 1.0, 1e3, "N, MPa"),
    "mm-ms-g": (1e-3, 1e-3, 1e-3, "N, MPa"),
    "cm-us-g": (1e-2, 1e-6, 1e-3, "1e7 N, Mbar"),
    "m-ms-kg": (1.0, 1e-3, 1.0, "MN, MPa"),
}


@dataclass(frozen=True)
class Units:
    """Factors from a deck's units to SI (multiply a deck value by one)."""

    name: str
    length: float
    time: float
    mass: float

    @classmethod
    def named(cls, name: str) -> "Units":
        if name not in SYSTEMS:
            raise ValueError(f"--units {name!r} is not a unit system sphdyn knows; "
                             f"give one of {', '.join(SYSTEMS)} (length-time-mass)")
        length, time, mass, _ = SYSTEMS[name]
        return cls(name, length, time, mass)

    @property
    def velocity(self) -> float:
        return self.length / self.time

    @property
    def density(self) -> float:
        return self.mass / self.length ** 3

    @property
    def stress(self) -> float:
        return self.mass / (self.length * self.time ** 2)


def help_text() -> str:
    """The systems for ``--help``."""
    return "; ".join(f"{k} ({v[3]})" for k, v in SYSTEMS.items())
