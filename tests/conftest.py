"""Test-session settings.

Tests use small particle counts, where the cost of waking a thread pool
dominates, so they run with one Numba thread unless SPHDYN_TEST_THREADS says
otherwise. Tests that check thread-count independence set their own counts.
"""

import os

import numba
import pytest


@pytest.fixture(autouse=True)
def _numba_threads():
    n = int(os.environ.get("SPHDYN_TEST_THREADS", "1"))
    numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))
    yield
