"""sphdyn: Smoothed Particle Hydrodynamics for structural dynamics (concrete under impact).

Today: SPH solids, the CSCM concrete model, heterogeneity (random masses,
initial cracks, mesostructure) and ensembles. Planned: explicit FEM, SPH-FEM
coupling, reinforcement and explosives.
"""

__version__ = "0.1.0"
