"""The tables of a deck, one module per group of sections.

The material tables are not here: each material model owns its table (its
``schema``, see :mod:`sphdyn.materials.registry`), built on
:class:`sphdyn.deck.sections.material.MaterialSection`.
"""
