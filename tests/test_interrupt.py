"""Stopped runs keep their work: SIGINT/SIGTERM, a full disk, the history flush."""

import errno
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from sphdyn.cli import main
from sphdyn.deck import loads_deck
from sphdyn.watchers.guards import SimulationFailed
from sphdyn.watchers.interrupt import StopRequests
from sphdyn.io import read_frame, read_history_csv
from sphdyn.watchers.monitors import HistoryFlush
from sphdyn.simulation import Simulation
from decks import SMALL_DISC

SRC = str(Path(__file__).resolve().parents[1] / "src")

# The small disc between a floor and a ceiling 30 mm apart, bouncing for 40 ms:
# about 11,000 steps, a few seconds of stepping, with a frame every 0.4 ms, so a
# signal sent once the first frames are on disk lands far before the end.
BOUNCING = SMALL_DISC.format(t_end="40 ms", ck=0).replace(
    'every = "0.5 ms"', 'every = "0.4 ms"').replace(
    "[output]", "[[wall]]\nname = \"ceiling\"\npoint = [0, 0.03, 0]\n"
    "normal = [0, -1, 0]\n[domain]\nlo = [-0.05, -0.01, 0]\nhi = [0.05, 0.04, 0]\n"
    "[output]")


def _cli(*args, **kw):
    env = dict(os.environ, PYTHONPATH=SRC + os.pathsep + os.environ.get("PYTHONPATH", ""))
    return subprocess.Popen([sys.executable, "-m", "sphdyn", *args], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)


def _frames(out: Path) -> list[Path]:
    return sorted((out / "frames").glob("*.h5")) if (out / "frames").exists() else []


@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_signalled_run_stops_cleanly_and_restarts_to_the_same_bits(tmp_path, sig, code):
    # The trial: a run killed mid-way lost everything. Now the first
    # SIGINT/SIGTERM finishes the step, writes checkpoint, history and summary,
    # exits 128 + signal with how to resume; the restart then ends exactly
    # (bitwise: every history column, every field of the last frame) where an
    # uninterrupted run ends. Both runs use the automatic thread count, so the
    # thread tuner may switch counts at different steps in the two: results
    # must not depend on it.
    deck = tmp_path / "bouncing.toml"
    deck.write_text(BOUNCING)
    full, cut = tmp_path / "full", tmp_path / "cut"
    assert _cli("run", str(deck), "--out", str(full), "-q").wait(timeout=600) == 0

    proc = _cli("run", str(deck), "--out", str(cut), "-q")
    deadline = time.monotonic() + 300
    while len(_frames(cut)) < 3 and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    proc.send_signal(sig)
    out, err = proc.communicate(timeout=300)
    assert proc.returncode == code, err
    summary = json.loads((cut / "summary.json").read_text())
    assert summary["status"] == "interrupted" and summary["signal"] == sig.name
    assert 0 < summary["time"] < 40e-3  # stopped mid-way, not at the end
    assert (cut / "checkpoint.h5").exists() and (cut / "history.csv").exists()
    assert "Traceback" not in err
    assert f"Resume with: sphdyn restart {cut}" in err
    assert len(err.strip().splitlines()) == 1, err  # one line, no traceback

    rest = _cli("restart", str(cut), "-q")
    _, err = rest.communicate(timeout=600)
    assert rest.returncode == 0, err
    h_full = read_history_csv(full / "history.csv")
    h_cut = read_history_csv(cut / "history.csv")
    assert list(h_full) == list(h_cut)
    for key in h_full:
        assert np.array_equal(h_full[key], h_cut[key]), key
    t_full, _, f_full, _ = read_frame(_frames(full)[-1])
    t_cut, _, f_cut, _ = read_frame(_frames(cut)[-1])
    assert t_full == t_cut
    for key in f_full:
        assert np.array_equal(f_full[key], f_cut[key]), key
    assert [p.name for p in _frames(full)] == [p.name for p in _frames(cut)]
    assert json.loads((cut / "summary.json").read_text())["status"] == "completed"


def test_stop_requests_turn_the_first_signal_into_a_flag():
    # in the main thread: the first SIGINT is a flag, a second one interrupts
    previous = signal.getsignal(signal.SIGINT)
    with StopRequests() as stop:
        assert not stop.requested
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.01)  # the handler runs between bytecodes
        assert stop.requested and stop.name == "SIGINT"
        with pytest.raises(KeyboardInterrupt):
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.01)
    assert signal.getsignal(signal.SIGINT) is previous  # restored


def _small(tmp_path, name, t_end="3 ms"):
    return Simulation.from_deck(loads_deck(SMALL_DISC.format(t_end=t_end, ck=0)),
                                tmp_path / name)


def test_an_interrupted_run_in_process_writes_everything(tmp_path):
    # the same path through the Python API: a monitor sends SIGTERM to its
    # own process at step 30; the run ends after that step
    sim = _small(tmp_path, "api")

    class Killer:
        def after_step(self, s):
            if s.step_count == 30:
                os.kill(os.getpid(), signal.SIGTERM)

    sim.stepper.add_monitor(Killer())
    summary = sim.run(threads=1)
    assert summary["status"] == "interrupted" and summary["signal"] == "SIGTERM"
    assert summary["steps"] == 30
    saved = json.loads((tmp_path / "api/summary.json").read_text())
    assert saved["status"] == "interrupted"
    h = read_history_csv(tmp_path / "api/history.csv")
    # rows are taken at the kick's time t^n of the step after: the kick of
    # step 29 recorded step 28 (history_every = 2); all rows so far are on disk
    assert h["step"][-1] == 28
    # the last state is the last frame (a stop frame, replaced on restart)
    t, step, _, attrs = read_frame(_frames(tmp_path / "api")[-1])
    assert (t, step) == (summary["time"], 30) and attrs.get("stop_frame")


def test_a_full_disk_stops_the_run_and_keeps_what_was_written(tmp_path, monkeypatch):
    # ENOSPC from the third frame on (and from every later write): the run
    # stops with a diagnosis naming the error, the two frames written before
    # are complete, and nothing raises but SimulationFailed.
    sim = _small(tmp_path, "full")
    real = sim.frames.write
    calls = []

    def write(*a, **k):
        calls.append(1)
        if len(calls) >= 3:
            raise OSError(errno.ENOSPC, "No space left on device",
                          str(tmp_path / "full/frames/frame_00002.h5"))
        return real(*a, **k)

    monkeypatch.setattr(sim.frames, "write", write)
    with pytest.raises(SimulationFailed) as info:
        sim.run(threads=1)
    msg = info.value.diagnosis
    assert "No space left on device" in msg and "frame_00002.h5" in msg
    assert "restart" in msg
    assert len(_frames(tmp_path / "full")) == 2
    for f in _frames(tmp_path / "full"):
        read_frame(f)  # complete files
    summary = json.loads((tmp_path / "full/summary.json").read_text())
    assert summary["status"] == "failed"
    assert (tmp_path / "full/history.csv").exists()


def test_the_cli_reports_a_full_disk_in_one_line(tmp_path, monkeypatch, capsys):
    deck = tmp_path / "d.toml"
    deck.write_text(SMALL_DISC.format(t_end="3 ms", ck=0))

    def no_space(self, *a, **k):
        raise OSError(errno.ENOSPC, "No space left on device")

    from sphdyn.io import FrameWriter

    monkeypatch.setattr(FrameWriter, "write", no_space)
    assert main(["run", str(deck), "--out", str(tmp_path / "o"), "-q"]) == 1
    err = capsys.readouterr().err
    assert "No space left on device" in err and "Traceback" not in err


def test_history_flush_keeps_the_file_within_its_interval():
    # a fake clock: 1 s per step; writes every 5 s, and the interval stretches
    # to 20x a slow write so rewriting a long history stays under 5 % of the run
    now = [0.0]
    writes = []

    def write():
        writes.append(now[0])
        now[0] += cost[0]

    cost = [0.0]
    flush = HistoryFlush(write, interval=5.0, clock=lambda: now[0])
    for _ in range(12):
        now[0] += 1.0
        flush.after_step(None)
    assert writes == [5.0, 10.0]
    cost[0] = 1.0  # a write now takes 1 s: next one 20 s after it ends
    for _ in range(60):
        now[0] += 1.0
        flush.after_step(None)
    gaps = np.diff(writes[1:])
    assert writes[2] == 15.0 and np.all(gaps[1:] >= 20.0), writes


def test_ctrl_c_outside_the_step_loop_is_one_line_and_130(tmp_path, monkeypatch, capsys):
    # e.g. while a big model is being built: no traceback, exit 130
    import sphdyn.build.model

    def slow_build(deck):
        raise KeyboardInterrupt

    monkeypatch.setattr(sphdyn.build.model, "build_model", slow_build)
    deck = tmp_path / "d.toml"
    deck.write_text(SMALL_DISC.format(t_end="3 ms", ck=0))
    assert main(["check", str(deck)]) == 130
    err = capsys.readouterr().err
    assert "interrupted" in err and "Traceback" not in err
