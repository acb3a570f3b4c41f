"""Validation against experiments (issue 53; docs/validation.md).

``sphdyn validate [CASE ...] [--quick]`` runs the cases of
:data:`~sphdyn.validation.cases.CASES` (decks in ``validation/cases/``),
reads the measured numbers from ``validation/data/``, measures the same
quantities on each run (:mod:`.measures`), compares them with verdicts
(:mod:`.report`) and writes the table, figures and, with ``--docs``, the
block of docs/validation.md.
"""
