"""The command line's argument types: thread counts, whole numbers, quantities
with units, writable folders (each a clear usage error, exit 2)."""

from __future__ import annotations

import argparse
from pathlib import Path


def _threads(n):
    """Set the Numba thread count; ``None`` leaves the automatic choice."""
    if n is not None:
        import numba

        numba.set_num_threads(n)


def _whole(lo: int):
    """An argparse type: a whole number of at least ``lo``."""
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or value < lo:
            raise argparse.ArgumentTypeError(
                f"{text!r} is not a whole number >= {lo}; give e.g. {max(lo, 1) * 2}")
        return value
    parse.__name__ = f"whole number >= {lo}"
    return parse


def _si(text: str, dim) -> float:
    """A quantity on the command line: a plain number is SI (as in decks),
    else a string with units ("250 us"); raises QuantityError."""
    from ..deck.units import to_si

    try:
        return float(text)
    except ValueError:
        return to_si(text, dim)


def _positive(dim_name: str):
    """An argparse type: a positive finite quantity of the deck dimension
    ``dim_name`` (``TIME``, ``MASS``, ...), plain numbers in SI."""
    from ..deck import units

    dim = getattr(units, dim_name)

    def parse(text: str) -> float:
        try:
            value = _si(text, dim)
        except units.QuantityError as exc:
            raise argparse.ArgumentTypeError(f"{exc.what}; {exc.fix}") from None
        if not value > 0 or value == float("inf"):
            raise argparse.ArgumentTypeError(
                f"{text!r} is not a positive finite {dim.name}; give e.g. "
                f"{dim.si_example:g} ({dim.si_name}) or '{dim.example}'")
        return value
    return parse


#: an argparse type: a time, plain numbers in seconds or with units ("250 us")
_duration = _positive("TIME")


def _writable_dir(path, flag: str) -> Path:
    """Check that directory ``path`` can be made and written, without making it.

    The path must not be a file or lie under one, and its nearest existing
    directory (itself, or the ancestor it would be made in) must take a new
    file. Raises a ValueError naming ``flag`` (the option that gave the path).
    """
    import tempfile

    path = Path(path)
    probe = path
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    if not probe.is_dir():
        what = "this is a file" if probe == path else f"{probe} is a file"
        raise ValueError(f"{flag} {path}: {what}, not a directory. "
                         f"Fix: give {flag} a directory (new or existing)")
    try:
        with tempfile.TemporaryFile(dir=probe):
            pass
    except OSError as exc:
        raise ValueError(f"{flag} {path}: cannot write there ({exc.strerror or exc}). "
                         f"Fix: give {flag} a directory you may write to") from None
    return path
