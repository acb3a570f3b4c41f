"""Numerical heterogeneity of SPH bodies.

Random particle-mass fields and initial cracks as zero-mass particles (the
paper "Inclusion of Randomness into SPH Simulations"), and concrete
mesostructure generated from fractal coherent noise or from a photo
(thesis chapter 7). Submodules are imported explicitly by their users.
"""
