"""Events: changes of the model between steps (see :mod:`sphdyn.events.base`)."""

from .base import Event
from .domain_exit import DomainExit
from .erosion import ElementErosion, ErosionRules
from .inject import InjectParticles

__all__ = ["DomainExit", "ElementErosion", "ErosionRules", "Event", "InjectParticles"]
