"""sphdyn: Smoothed Particle Hydrodynamics and explicit FEM for structural dynamics."""

__version__ = "0.1.0"
