"""Stop requests: SIGINT and SIGTERM end a run cleanly at the next step boundary.

As LS-DYNA's sense switches do, the first SIGINT (Ctrl-C) or SIGTERM (a
cluster's time limit, ``kill``, Dask cancelling a sample) does not kill the
run: the step in progress finishes, then :class:`~sphdyn.simulation.Simulation`
writes a checkpoint, the history, the plots and ``summary.json`` with status
``"interrupted"``, and the command line exits with 128 + the signal number
(130 for SIGINT, 143 for SIGTERM). A second signal while the run is being
wound up stops at once (Python's default ``KeyboardInterrupt`` / exit).

Handlers can only be installed in the main thread of the main interpreter;
elsewhere (a Dask worker thread) :class:`StopRequests` installs nothing and a
run is stopped by its host as before.
"""

from __future__ import annotations

import signal
import threading

#: the signals that ask a run to stop, and the exit code the CLI returns for each
SIGNALS = {signal.SIGINT: 128 + signal.SIGINT, signal.SIGTERM: 128 + signal.SIGTERM}


class StopRequests:
    """Context manager: while inside, the first SIGINT/SIGTERM sets :attr:`signum`
    instead of stopping the process; a second one raises ``KeyboardInterrupt``
    (SIGINT) or ``SystemExit(143)`` (SIGTERM).

    The previous handlers are restored on exit.
    """

    def __init__(self) -> None:
        self.signum: int | None = None
        self._previous: dict[int, object] = {}

    @property
    def requested(self) -> bool:
        """True once a stop was asked for."""
        return self.signum is not None

    @property
    def name(self) -> str | None:
        """``"SIGINT"`` or ``"SIGTERM"`` once a stop was asked for."""
        return None if self.signum is None else signal.Signals(self.signum).name

    def _handle(self, signum, frame) -> None:
        if self.signum is None:
            self.signum = signum
            return
        if signum == signal.SIGINT:
            raise KeyboardInterrupt
        raise SystemExit(SIGNALS[signal.SIGTERM])

    def __enter__(self) -> "StopRequests":
        if threading.current_thread() is threading.main_thread():
            for sig in SIGNALS:
                try:
                    self._previous[sig] = signal.signal(sig, self._handle)
                except (ValueError, OSError):  # not the main interpreter
                    pass
        return self

    def __exit__(self, *exc) -> None:
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)
        self._previous.clear()
