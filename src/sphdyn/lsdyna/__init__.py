"""LS-DYNA keyword decks into sphdyn decks (``sphdyn import``).

:func:`import_deck` reads a keyword deck (:mod:`.scan`, :mod:`.reader`),
maps its keywords (:mod:`.convert`; the table in docs/lsdyna.md) and writes
the sphdyn deck with its data files: the solid elements as an Abaqus
``.inp`` mesh whose element sets are the parts and whose node sets are the
constrained nodes, the SPH particles of each part as a ``points`` CSV.
"""

from __future__ import annotations

from pathlib import Path

from .convert import Dropped, Imported, convert
from .reader import read_keyword_deck
from .scan import KeywordError
from .units import SYSTEMS, Units

__all__ = ["Dropped", "Imported", "KeywordError", "SYSTEMS", "import_deck", "write_import"]


def import_deck(path, units: str, stem: str | None = None) -> Imported:
    """The sphdyn deck of keyword deck ``path`` in unit system ``units``
    (:data:`~.units.SYSTEMS`), its data files named after ``stem`` (default:
    the keyword file's name). Raises :class:`KeywordError` for a deck that
    cannot be read."""
    kd = read_keyword_deck(path)
    return convert(kd, Units.named(units), stem or Path(path).stem)


def write_import(imported: Imported, deck_path) -> list[Path]:
    """Write the deck to ``deck_path`` and its data files beside it
    (atomically, each); the paths written."""
    import tomli_w

    from ..io.atomic import atomic_path

    deck_path = Path(deck_path)
    home = deck_path.parent
    home.mkdir(parents=True, exist_ok=True)
    written = []
    for name, data in imported.files.items():
        target = home / name
        with atomic_path(target) as tmp:
            if name.endswith(".csv"):
                _write_points(tmp, data)
            else:
                import meshio

                meshio.write(tmp, data, file_format="abaqus")
        written.append(target)
    header = ("# written by sphdyn import from an LS-DYNA keyword deck; what was not "
              "imported:\n" + "".join(f"#   {d.line()}\n" for d in imported.dropped)
              if imported.dropped else "# written by sphdyn import\n")
    with atomic_path(deck_path) as tmp:
        Path(tmp).write_text(header + tomli_w.dumps(imported.deck))
    written.append(deck_path)
    return written


def _write_points(path, x) -> None:
    """A points file (:func:`sphdyn.geometry.lattice.read_points`): a header and
    one particle per row, every digit kept."""
    with open(path, "w") as f:
        f.write("x,y,z\n")
        for p in x:
            f.write(",".join(repr(float(c)) for c in p) + "\n")
