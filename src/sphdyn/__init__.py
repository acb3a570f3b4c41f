"""sphdyn: Smoothed Particle Hydrodynamics for structural dynamics (concrete under impact).

SPH solids (updated- and total-Lagrangian), the CSCM concrete model, explicit
finite elements (hex8, quad4, beams, trusses) coupled to SPH (penalty, tied,
hybrid; elements eroding into particles), rebar (sublayer and embedded),
explosives (JWL, ideal gas) and empirical air-blast loads, heterogeneity
(random masses, initial cracks, mesostructure) and ensembles. README.md lists
what each deck table does.
"""

__version__ = "0.1.0"
