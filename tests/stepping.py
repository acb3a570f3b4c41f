"""Test helpers around the stepper: build one from a deck, step with the record."""

from sphdyn.assembly import build_stepper  # noqa: F401  (re-exported for the tests)


class _Grab:
    def __init__(self):
        self.row = None

    def after_kick(self, s):
        self.row = s.record()


def step(s, t_stop=None) -> dict:
    """One step of stepper ``s``; returns its energy record at the kick's time."""
    grab = _Grab()
    s.add_monitor(grab)
    try:
        s.step(t_stop)
    finally:
        s.monitors.remove(grab)
    return grab.row


def wall(s, name):
    """The wall interaction called ``name``."""
    return next(i for i in s.interactions if i.name == name)
