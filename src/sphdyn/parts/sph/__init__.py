"""The SPH part: updated- and total-Lagrangian solid schemes and their remedies.

:mod:`.passes` (updated-Lagrangian gather passes), :mod:`.total_lagrangian`
and :mod:`.tl_scheme` (total-Lagrangian kernel), :mod:`.artificial_stress`,
:mod:`.swegle` (tensile-instability indicator) and :mod:`.part` (the
:class:`SPHPart` that orders them in a step).
"""
