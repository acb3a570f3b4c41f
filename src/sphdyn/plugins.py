"""What other packages bring through entry points: material models
(``sphdyn.materials``) and builders of parts and interactions
(``sphdyn.builders``).

An entry point names an object of the expected type, or a callable that
returns one (or registers it itself and returns None). Each group is loaded
once, when its registry is first asked (:data:`LOADED`); a failing entry
point is skipped with a ``RuntimeWarning``, so a broken plugin never stops a
deck that does not use it.
"""

from __future__ import annotations

import warnings
from importlib.metadata import entry_points
from typing import Callable


#: the groups loaded so far; a group taken out is loaded again when next asked (tests)
LOADED: frozenset[str] = frozenset()


def load_group(group: str, kind: type, add: Callable[[object], None]) -> None:
    """Once per group: call ``add(obj)`` for each object of type ``kind`` the
    entry points of ``group`` give (each loaded, called if it is not a
    ``kind``)."""
    global LOADED
    if group in LOADED:
        return
    LOADED = LOADED | {group}
    for ep in entry_points(group=group):
        try:
            found = ep.load()
            obj = found if isinstance(found, kind) else found()
            if isinstance(obj, kind):
                add(obj)
        except Exception as exc:  # a broken plugin must not stop every deck
            warnings.warn(f"{group} entry point {ep.name!r} ({ep.value}) was skipped: "
                          f"{exc}", RuntimeWarning, stacklevel=3)
