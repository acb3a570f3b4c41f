"""Measured data of ``validation/data/``: the CSV files and their provenance.

Each file starts with ``#`` lines naming the data set, its source and where
the values were read (validation/data/SOURCES.md), then a CSV header and
rows. :func:`read` returns the rows as dictionaries of strings (a cell may
hold a number, a word or a note); :func:`number` converts one cell.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class DataFile:
    """One measured data set: its ``#`` provenance lines and its rows."""

    path: Path
    provenance: tuple[str, ...]
    rows: tuple[dict[str, str], ...]

    def row(self, **match: str) -> dict[str, str]:
        """The one row whose columns equal ``match``; ``KeyError`` naming the
        file and the match if there is not exactly one."""
        found = [r for r in self.rows if all(r.get(k) == v for k, v in match.items())]
        if len(found) != 1:
            raise KeyError(f"{self.path.name}: {len(found)} rows match {match}")
        return found[0]


def read(path: Path) -> DataFile:
    """The data file at ``path`` (``FileNotFoundError`` if missing)."""
    lines = Path(path).read_text(encoding="utf-8").splitlines()
    provenance = tuple(ln for ln in lines if ln.startswith("#"))
    body = "\n".join(ln for ln in lines if ln.strip() and not ln.startswith("#"))
    rows = tuple(csv.DictReader(io.StringIO(body)))
    return DataFile(Path(path), provenance, rows)


def number(row: dict[str, str], column: str) -> float:
    """Cell ``column`` of ``row`` as a float (``ValueError`` naming the
    column if it is not a number)."""
    try:
        return float(row[column])
    except (KeyError, ValueError) as exc:
        raise ValueError(f"column {column!r} of row {row} is not a number") from exc
