"""Atomic file replacement: a crash never leaves a half-written output file.

Every writer in :mod:`sphdyn.io` writes into a temporary file in the *same
directory* as the target (hence on the same filesystem), flushes it to disk and
then renames it onto the target with :func:`os.replace`, which is atomic on
POSIX and Windows. Readers therefore see either the complete old file or the
complete new file, never a mixture. If the writer raises, the temporary file is
deleted and the old file is left untouched.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = ["atomic_path", "atomic_write_text", "atomic_write_bytes"]


def _read_umask() -> int:
    # os.umask can only be read by setting it; done once at import time.
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


_UMASK = _read_umask()


def _fsync_file(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _fsync_dir(directory: Path) -> None:
    """Persist the rename itself (best effort: not possible on every OS)."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


@contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path that replaces ``path`` when the block succeeds.

    The temporary file is created (empty) next to ``path``; the caller writes
    to it by name, with any library (h5py, meshio, matplotlib, ...). On normal
    exit it is fsync'ed and atomically renamed onto ``path``; on an exception
    it is deleted and ``path`` is left as it was. Missing parent directories
    are created.

    Parameters
    ----------
    path : str or os.PathLike
        Final destination of the file.

    Yields
    ------
    pathlib.Path
        Temporary file in the same directory as ``path``.

    Examples
    --------
    >>> with atomic_path("out/result.h5") as tmp:          # doctest: +SKIP
    ...     with h5py.File(tmp, "w") as f:
    ...         f["x"] = x
    """
    path = Path(path)
    directory = path.parent
    directory.mkdir(parents=True, exist_ok=True)
    fd, tmp_name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp",
                                    dir=directory)
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        yield tmp
        # mkstemp creates mode 0600; give the result the permissions a plain
        # open() would have given it (or keep those of the file it replaces).
        try:
            mode = path.stat().st_mode & 0o7777
        except FileNotFoundError:
            mode = 0o666 & ~_UMASK
        os.chmod(tmp, mode)
        _fsync_file(tmp)
        os.replace(tmp, path)
    except BaseException:
        try:
            tmp.unlink()
        except FileNotFoundError:
            pass
        raise
    _fsync_dir(directory)


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> Path:
    """Atomically replace ``path`` by ``data``.

    Returns
    -------
    pathlib.Path
        The path written.
    """
    path = Path(path)
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as f:
            f.write(data)
    return path


def atomic_write_text(path: str | os.PathLike, text: str,
                      encoding: str = "utf-8") -> Path:
    """Atomically replace ``path`` by ``text`` (newlines written as given).

    Returns
    -------
    pathlib.Path
        The path written.
    """
    return atomic_write_bytes(path, text.encode(encoding))
