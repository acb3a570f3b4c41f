"""Project-wide policy of the compiled kernels.

Every Numba kernel uses ``error_model="numpy"``: a division by zero or a math
domain error gives inf/NaN, which the run's guards (sphdyn.watchers.guards) stop with
a diagnosis. Under Numba's default "python" model such an error raises, and
inside a ``prange`` region the exception is swallowed and resurfaces later
as an unrelated ``SystemError`` (seen with the CSCM Lode ratio, 2026-11-22).
"""

import importlib
import pkgutil

import numpy as np
from numba import njit, prange
from numba.core.registry import CPUDispatcher

import sphdyn


def _kernels():
    found = {}
    for mod in pkgutil.walk_packages(sphdyn.__path__, "sphdyn."):
        if mod.name == "sphdyn.__main__":  # runs the command line on import
            continue
        module = importlib.import_module(mod.name)
        for name, obj in vars(module).items():
            if isinstance(obj, CPUDispatcher) and obj.__module__ == mod.name:
                found[f"{mod.name}.{name}"] = obj
    return found


def test_every_kernel_uses_the_numpy_error_model():
    kernels = _kernels()
    assert len(kernels) >= 100  # the scan finds them (110 on 2026-11-23)
    wrong = [k for k, f in kernels.items()
             if f.targetoptions.get("error_model") != "numpy"]
    assert wrong == []


def test_numpy_error_model_turns_a_zero_division_in_prange_into_nan():
    # What the policy buys: 0/0 and 2/0 inside a parallel loop give NaN and
    # inf, values the guards see. (Under the default model the same loop
    # raises on one thread, and the parallel region drops the exception.)
    @njit(parallel=True, error_model="numpy")
    def divide(a, b, out):
        for i in prange(a.size):
            out[i] = a[i] / b[i]

    out = np.zeros(3)
    divide(np.array([1.0, 0.0, 2.0]), np.array([1.0, 0.0, 0.0]), out)
    assert out[0] == 1.0 and np.isnan(out[1]) and out[2] == np.inf
