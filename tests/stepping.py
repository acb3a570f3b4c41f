"""Test helpers around the stepper: build one from a deck, step with the record."""

from sphdyn.build import build_stepper  # noqa: F401  (re-exported for the tests)


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


def restarted_pair(deck, advance, steps: int):
    """Two steppers of ``deck``: one run on, one restored from the first's
    state after ``advance(stepper)`` and run the same ``steps`` steps; both
    returned, for a bitwise comparison of a restart."""
    import copy

    st = build_stepper(deck)
    advance(st)
    scalars, groups = copy.deepcopy(st.state())
    for _ in range(steps):
        st.step()
    st2 = build_stepper(deck)
    st2.restore(scalars, groups)
    for _ in range(steps):
        st2.step()
    return st, st2
