"""Events: changes of the model between steps (see :mod:`sphdyn.events.base`)."""

from .base import Event
from .inject import InjectParticles

__all__ = ["Event", "InjectParticles"]
