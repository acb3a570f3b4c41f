"""Per-item arrays with a capacity: the one place where a model grows.

An :class:`ArrayStore` keeps every per-item array of a part (particles now,
mesh nodes later) in one table: state arrays that make up a checkpoint and
work arrays the passes use as scratch. Each array is allocated with a
capacity of rows and exposed as an ordinary attribute holding the view of
its first ``n`` rows, so Numba kernels see plain C-contiguous arrays of
length ``n``. :meth:`ArrayStore.grow` adds rows to *every* registered array
at once (reallocating with 1.5x headroom when the capacity is exhausted) and
tells the listeners (neighbour lists, material groups, walls) to refresh
what they derived from the old length.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

STATE = "state"  # part of a checkpoint and of the run's state
WORK = "work"  # scratch or derived data, rebuilt after a restart or a resize


class ArrayStore:
    """Named arrays of shape ``(n, *tail)`` sharing one row count ``n``.

    Attributes named after the registered arrays are the views ``full[:n]``;
    assigning an array of ``n`` rows to such an attribute replaces its
    storage. Listeners registered with :meth:`on_grow` are called as
    ``listener(n_old, n_new)`` after every :meth:`grow`.
    """

    def __init__(self, n: int):
        object.__setattr__(self, "_n", int(n))
        object.__setattr__(self, "_full", {})
        object.__setattr__(self, "_kind", {})
        object.__setattr__(self, "_fill", {})
        object.__setattr__(self, "_listeners", [])

    # ------------------------------------------------------------ registry
    @property
    def n(self) -> int:
        """Number of items (rows in use)."""
        return self._n

    @property
    def capacity(self) -> int:
        """Rows allocated (the same for every array)."""
        full = next(iter(self._full.values()), None)
        return self._n if full is None else full.shape[0]

    def add(self, name: str, tail: tuple = (), dtype=np.float64, kind: str = WORK,
            fill=0) -> np.ndarray:
        """Register an array ``(n, *tail)`` filled with ``fill``; returns its view.

        Registering an existing name returns the existing view (so a pass can
        ask for its work array idempotently) if shape and dtype agree.
        """
        if name in self._full:
            full = self._full[name]
            if full.shape[1:] != tuple(tail) or full.dtype != np.dtype(dtype):
                raise ValueError(f"array {name!r} exists with shape {full.shape[1:]} "
                                 f"and dtype {full.dtype}, asked {tail} {dtype}")
            return getattr(self, name)
        if kind not in (STATE, WORK):
            raise ValueError(f"kind must be {STATE!r} or {WORK!r}, got {kind!r}")
        full = np.full((self.capacity,) + tuple(tail), fill, dtype=dtype)
        self._full[name] = full
        self._kind[name] = kind
        self._fill[name] = fill
        object.__setattr__(self, name, full[: self._n])
        return getattr(self, name)

    def names(self, kind: str | None = None) -> list[str]:
        """Registered array names (of one kind, if given), in registration order."""
        return [k for k, v in self._kind.items() if kind is None or v == kind]

    def __setattr__(self, name, value):
        if name in self._full:  # copy into the storage: views held elsewhere stay valid
            view = getattr(self, name)
            value = np.asarray(value)
            if value.shape != view.shape:
                raise ValueError(f"{name}: shape {value.shape} does not fit {view.shape}")
            view[...] = value
        else:
            object.__setattr__(self, name, value)

    def arrays(self, kind: str = STATE) -> dict[str, np.ndarray]:
        """The views of every array of ``kind`` by name (checkpoints use STATE)."""
        return {k: getattr(self, k) for k in self.names(kind)}

    # -------------------------------------------------------------- growth
    def on_grow(self, listener: Callable[[int, int], None]) -> None:
        """Call ``listener(n_old, n_new)`` after each :meth:`grow`."""
        self._listeners.append(listener)

    def _reallocate(self, capacity: int) -> None:
        for name, old in self._full.items():
            if old.shape[0] == capacity:
                continue
            new = np.full((capacity,) + old.shape[1:], self._fill[name], dtype=old.dtype)
            m = min(old.shape[0], capacity)
            new[:m] = old[:m]
            self._full[name] = new

    def _refresh_views(self) -> None:
        for name, full in self._full.items():
            object.__setattr__(self, name, full[: self._n])

    def grow(self, k: int, notify: bool = True) -> slice:
        """Add ``k`` rows to every array; returns the slice of the new rows.

        New rows hold each array's fill value (rows beyond ``n`` are never
        written: they keep the value they were allocated with). The views are replaced (old
        views still point at the old rows); listeners are then called, unless
        ``notify`` is False: the caller fills the new rows first and then
        calls :meth:`notify_grown`.
        """
        if k < 0:
            raise ValueError(f"cannot grow by {k} rows")
        n_old, n_new = self._n, self._n + int(k)
        if n_new > self.capacity:
            self._reallocate(max(n_new, int(1.5 * self.capacity) + 1))
        object.__setattr__(self, "_n", n_new)
        self._refresh_views()
        if notify:
            self.notify_grown(n_old, n_new)
        return slice(n_old, n_new)

    def notify_grown(self, n_old: int, n_new: int) -> None:
        """Tell the listeners that rows ``n_old:n_new`` were added."""
        for listener in self._listeners:
            listener(n_old, n_new)
