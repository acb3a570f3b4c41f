"""Time histories of global quantities (energies, contact forces, time step).

A :class:`History` is a table of floats with fixed columns, one row per
recorded step. It is saved as CSV (header line, then rows, floats written with
``repr`` so they read back bit for bit) by a full atomic rewrite, so the file on
disk is always complete. On restart, :meth:`History.from_csv` reloads it and
:meth:`History.truncate_after` drops the rows past the restart time.
"""

from __future__ import annotations

import csv
import io
import os
from pathlib import Path

import numpy as np

from .atomic import atomic_write_text

__all__ = ["History", "read_history_csv"]


class History:
    """Growable table of float rows with columns fixed by the first row.

    Parameters
    ----------
    time_key : str, optional
        Name of the time column used by :meth:`truncate_after`.

    Examples
    --------
    >>> h = History()
    >>> h.append({"time": 0.0, "E_kinetic": 1.0})
    >>> h.append({"time": 1e-6, "E_kinetic": 0.9})
    >>> h.columns
    ['time', 'E_kinetic']
    """

    def __init__(self, time_key: str = "time") -> None:
        self.time_key = time_key
        self._columns: list[str] = []
        self._rows: list[tuple[float, ...]] = []

    @property
    def columns(self) -> list[str]:
        """Column names, in the order of the first row's keys."""
        return list(self._columns)

    def __len__(self) -> int:
        return len(self._rows)

    def append(self, row: dict[str, float]) -> None:
        """Add one row.

        The first row fixes the columns (and their order); every later row
        must have exactly the same keys, in any order.

        Raises
        ------
        ValueError
            If the keys differ from the columns, or a column name contains a
            comma, quote or newline (not representable in the CSV header).
        """
        if not self._columns:
            if not row:
                raise ValueError("the first history row must not be empty")
            bad = [k for k in row if not k or any(c in k for c in ',"\n\r')]
            if bad:
                raise ValueError(f"invalid history column names: {bad}")
            self._columns = list(row)
        elif row.keys() != set(self._columns):
            missing = [k for k in self._columns if k not in row]
            extra = [k for k in row if k not in self._columns]
            raise ValueError(f"history row keys differ from the columns: "
                             f"missing {missing}, unexpected {extra}")
        self._rows.append(tuple(float(row[k]) for k in self._columns))

    def as_arrays(self) -> dict[str, np.ndarray]:
        """Each column as a float64 array (empty dict before the first row)."""
        table = np.array(self._rows, dtype=np.float64).reshape(len(self._rows),
                                                               len(self._columns))
        return {k: table[:, j].copy() for j, k in enumerate(self._columns)}

    def truncate_after(self, t: float) -> int:
        """Drop the rows with ``time > t`` (for a restart at time ``t``).

        Returns
        -------
        int
            Number of rows removed.
        """
        if not self._rows:
            return 0
        if self.time_key not in self._columns:
            raise KeyError(f"history has no {self.time_key!r} column")
        j = self._columns.index(self.time_key)
        kept = [r for r in self._rows if r[j] <= t]
        removed = len(self._rows) - len(kept)
        self._rows = kept
        return removed

    def to_csv_text(self) -> str:
        """The CSV text written by :meth:`write_csv`."""
        lines = [",".join(self._columns)]
        lines.extend(",".join(map(repr, r)) for r in self._rows)
        return "\n".join(lines) + "\n"

    def write_csv(self, path: str | os.PathLike) -> Path:
        """Atomically (re)write the whole table as CSV.

        Returns
        -------
        pathlib.Path
            The path written.
        """
        return atomic_write_text(path, self.to_csv_text())

    @classmethod
    def from_csv(cls, path: str | os.PathLike, time_key: str = "time") -> "History":
        """Load a table written by :meth:`write_csv` (to continue it on restart)."""
        columns, rows = _parse_csv(path)
        h = cls(time_key=time_key)
        h._columns = columns
        h._rows = rows
        return h


def _parse_csv(path: str | os.PathLike) -> tuple[list[str], list[tuple[float, ...]]]:
    text = Path(path).read_text(encoding="utf-8")
    reader = csv.reader(io.StringIO(text))
    try:
        columns = next(reader)
    except StopIteration:
        return [], []
    rows = []
    for lineno, rec in enumerate(reader, start=2):
        if not rec:
            continue
        if len(rec) != len(columns):
            raise ValueError(f"{path}:{lineno}: {len(rec)} values, "
                             f"expected {len(columns)}")
        rows.append(tuple(float(v) for v in rec))
    return columns, rows


def read_history_csv(path: str | os.PathLike) -> dict[str, np.ndarray]:
    """Read a history CSV into one float64 array per column."""
    columns, rows = _parse_csv(path)
    table = np.array(rows, dtype=np.float64).reshape(len(rows), len(columns))
    return {k: table[:, j].copy() for j, k in enumerate(columns)}
