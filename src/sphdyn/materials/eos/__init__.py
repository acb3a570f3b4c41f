"""Equations of state of fluids: pressure from density and internal energy.

Both are of the form ``p = a(V) + b(V) e`` (linear in the specific internal
energy ``e`` at fixed density), which lets the fluid update solve its energy
equation exactly (:func:`sphdyn.materials.fluid.fluid_step`):

* :mod:`.jwl`: Jones-Wilkins-Lee, detonation products;
* :mod:`.polynomial`: LS-DYNA's linear polynomial, with the ideal gas as a
  special case.
"""

from .jwl import cj_state, jwl_hugoniot_pressure, jwl_parts, jwl_pressure, jwl_sound_speed
from .polynomial import polynomial_parts, polynomial_pressure, polynomial_sound_speed

__all__ = ["cj_state", "jwl_hugoniot_pressure", "jwl_parts", "jwl_pressure",
           "jwl_sound_speed", "polynomial_parts", "polynomial_pressure",
           "polynomial_sound_speed"]
