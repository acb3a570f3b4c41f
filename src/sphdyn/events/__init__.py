"""Events: changes of the model between steps (see :mod:`sphdyn.events.base`)."""

from .base import Event
from .erosion import ElementErosion, ErosionRules
from .inject import InjectParticles

__all__ = ["ElementErosion", "ErosionRules", "Event", "InjectParticles"]
