"""The same deck gives the same bits whether its kernels were compiled in the
process or loaded from Numba's on-disk cache.

Two runs in subprocesses share one empty cache directory: the first compiles
every kernel and fills the cache, the second loads them. Floating-point
licences (fastmath reassociation and contraction) broke this: the compiled and
the cached total-Lagrangian pair loops rounded differently, and the
penetration at 600 m/s stopped in one process and ran through in the other.
The cases: the total-Lagrangian rings (the pair loops) and the erosion into SPH
of the penetration deck (a total-Lagrangian projectile, CSCM elements, penalty
contact, eroded elements become particles).
"""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np

CASES = ("rings_gray2001_total_lagrangian", "penetration_sph")


def test_compiled_and_cached_kernels_give_the_same_bits(tmp_path):
    script = Path(__file__).with_name("regression_cases.py")
    env = dict(os.environ, NUMBA_NUM_THREADS="1", NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    runs = []
    for k in range(2):
        out = tmp_path / f"run{k}"
        subprocess.run([sys.executable, str(script), "--out", str(out), *CASES],
                       check=True, env=env, capture_output=True)
        runs.append(out)
    assert any(Path(env["NUMBA_CACHE_DIR"]).rglob("*.nbi"))  # the second run loaded these
    for name in CASES:
        a, b = (dict(np.load(r / f"{name}.npz")) for r in runs)
        assert a.keys() == b.keys()
        for key in a:
            assert np.array_equal(a[key], b[key], equal_nan=True), (name, key)
