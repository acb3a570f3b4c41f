"""The automatic thread count: the tuner's choice, and results independent of it."""

import numba
import numpy as np
import pytest

from sphdyn.deck import loads_deck
from sphdyn.simulation import Simulation
from sphdyn.watchers.threads import ThreadTuner
from decks import concrete_disc_2d


class _Kin:
    n = 1000


class _Part:
    kin = _Kin()


class _Stepper:
    parts = [_Part()]


def _drive(tuner, cost, steps):
    """Run ``steps`` fake steps; ``cost(threads, step)`` is a step's seconds."""
    now = [0.0]
    tuner.clock = lambda: now[0]
    used = []
    s = _Stepper()
    for k in range(steps):
        tuner.before_step(s, 0.0, 0, None)
        now[0] += cost(tuner.active, k)
        used.append(tuner.active)
        tuner.after_step(s)
    return used


def _tuner(load=-2.0, **kw):
    """A 2-thread tuner; ``load`` as machine_load() gives it (-2: idle 2 cores)."""
    calls = []
    t = ThreadTuner(2, window=0.25, period=10.0, min_steps=8, warmup=5,
                    max_period=80.0, set_threads=calls.append, load=load, **kw)
    return t, calls


def test_on_a_loaded_machine_the_tuner_moves_to_one_thread():
    # measured on this machine (BENCHMARKS.md): with a competing process,
    # 2 threads ran at 0.74x the 1-thread speed
    tuner, calls = _tuner()
    used = _drive(tuner, lambda n, k: 0.010 if n == 1 else 0.0135, 8000)
    assert tuner.current == 1 and tuner.switches == 1
    # the switch happens after warm-up + one reference window + one trial
    # window (0.25 s, >= 8 steps each): within the first 5 + 19 + 25 steps
    assert used.index(1) < 5 + 20 and all(n == 1 for n in used[50:200])
    # re-trials of 2 threads after 10, 20, 40, 80 s of stepping, each one
    # window of 0.25 s: under 2 % of the steps run on the slow count
    assert used[50:].count(2) / len(used[50:]) < 0.02
    trial_starts = [k for k in range(51, len(used)) if used[k] == 2 and used[k - 1] == 1]
    gaps = np.diff(trial_starts) * 0.010  # seconds of stepping between trials
    assert len(gaps) == 2 and np.allclose(gaps, [20.3, 40.3], atol=0.15), gaps
    assert calls[0] == 2 and calls[-1] in (1, 2)


def test_on_an_idle_machine_the_tuner_keeps_all_threads():
    tuner, _ = _tuner()
    used = _drive(tuner, lambda n, k: 0.010 if n == 2 else 0.018, 3000)
    assert tuner.current == 2 and tuner.switches == 0
    assert tuner.trials >= 2  # it keeps looking: loads come and go
    assert used.count(1) / len(used) < 0.02


def test_noise_within_the_margin_does_not_flip_the_choice():
    # 1 thread 2 % faster (within the 3 % margin): stay where we are
    tuner, _ = _tuner()
    _drive(tuner, lambda n, k: 0.0100 if n == 2 else 0.0098, 3000)
    assert tuner.current == 2 and tuner.switches == 0


def test_the_tuner_follows_a_load_that_comes_and_goes():
    # loaded for the first 1500 steps (1 thread faster), idle after
    tuner, _ = _tuner()

    def cost(n, k):
        if k < 1500:
            return 0.010 if n == 1 else 0.0135
        return 0.010 if n == 2 else 0.018

    used = _drive(tuner, cost, 4000)
    assert 1 in used[:1500] and tuner.current == 2 and tuner.switches == 2


def test_a_machine_already_loaded_starts_on_one_thread():
    # load average 1.1 on 2 cores (machine_load -0.9 > -2 + 0.75): start on
    # 1 thread; the first trial of 2 threads finds them slower and stays
    tuner, calls = _tuner(load=-0.9)
    used = _drive(tuner, lambda n, k: 0.010 if n == 1 else 0.0135, 400)
    assert calls[0] == 1 and used[0] == 1 and tuner.start == 1
    assert tuner.current == 1 and tuner.switches == 0 and tuner.trials == 1
    # ... and on an idle machine it moves to 2 threads after its first trial
    tuner, _ = _tuner(load=-0.9)
    used = _drive(tuner, lambda n, k: 0.010 if n == 2 else 0.018, 400)
    assert tuner.current == 2 and tuner.switches == 1 and used.index(2) < 25


def test_long_steps_space_the_trials_by_their_window():
    # steps of a second (the 5 mm blast slab's detonation) and 1.4 s on one
    # thread: a trial window is min_steps = 8 of them, 11.2 s, 44.8 times the
    # nominal 0.25 s, so the schedule stretches by 44.8: the next trials come
    # 20 x 44.8 = 896 and 40 x 44.8 = 1792 s of stepping after the trial
    # window (8 steps) ends, not 20 and 40 s (without the stretch: 11.2 s on
    # the slow count per 20-80 s, 12-36 % of the run)
    tuner, _ = _tuner()
    used = _drive(tuner, lambda n, k: 1.0 if n == 2 else 1.4, 3000)
    assert tuner.current == 2 and tuner.switches == 0
    starts = [k for k in range(1, len(used)) if used[k] == 1 and used[k - 1] == 2]
    assert np.array_equal(np.diff(starts), [8 + 896, 8 + 1792]), starts
    slow = 1.4 * used.count(1)  # seconds on one thread: three trials, 33.6 s
    assert slow == pytest.approx(3 * 8 * 1.4) and slow / (slow + used.count(2)) < 0.012


def test_a_big_node_tries_half_its_cores():
    tuner = ThreadTuner(32, set_threads=lambda n: None, load=-32.0)
    assert tuner.start == 32 and tuner.other == 16


def test_the_tuner_needs_two_threads_to_choose_from():
    with pytest.raises(ValueError):
        ThreadTuner(1, set_threads=lambda n: None)


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="needs 2 threads")
def test_one_and_two_threads_give_the_same_bits(tmp_path):
    # the tuner may switch at any step, so a run must not depend on the count:
    # every loop writes its own rows and the kick's energy sums go block by
    # block in a fixed order (3 blocks of 1024 here, so the order matters)
    text = concrete_disc_2d("1.6 mm", "20 us", "10 us", ["velocity", "stress", "damage"])
    runs = {}
    for threads in (1, 2):
        sim = Simulation.from_deck(loads_deck(text), tmp_path / f"t{threads}")
        assert sim.particles.n > 2 * 1024
        sim.run(threads=threads)
        runs[threads] = sim
    a, b = runs[1], runs[2]
    for name in a.particles.names():
        assert np.array_equal(getattr(a.particles, name), getattr(b.particles, name),
                              equal_nan=True), name
    ha, hb = a.history.as_arrays(), b.history.as_arrays()
    for key in ha:
        assert np.array_equal(ha[key], hb[key]), key
