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


def _unpacked_writes(fn) -> list[str]:
    """Names unpacked from a tuple parameter (``a, b = param``) that the
    function writes by subscript (``a[i] = ...``, ``a[i] += ...``)."""
    import ast
    import inspect
    import textwrap

    tree = ast.parse(textwrap.dedent(inspect.getsource(fn)))
    func = tree.body[0]
    params = {a.arg for a in func.args.args}
    unpacked = set()
    for node in ast.walk(func):
        if (isinstance(node, ast.Assign) and isinstance(node.value, ast.Name)
                and node.value.id in params and isinstance(node.targets[0], ast.Tuple)):
            unpacked |= {e.id for e in node.targets[0].elts if isinstance(e, ast.Name)}
    written = set()
    for node in ast.walk(func):
        targets = (node.targets if isinstance(node, ast.Assign)
                   else [node.target] if isinstance(node, ast.AugAssign) else [])
        for t in targets:
            for sub in ast.walk(t):
                if isinstance(sub, ast.Subscript) and isinstance(sub.value, ast.Name) \
                        and sub.value.id in unpacked:
                    written.add(sub.value.id)
    return sorted(written)


def test_no_parallel_kernel_writes_an_array_unpacked_from_a_tuple():
    # Numba's parallel loops drop the writes into an array unpacked from a
    # tuple argument (found in issue 54's split of penalty_coupling_forces: a
    # spring's stiffness never reset); reads are fine. So a parallel kernel
    # takes the arrays it writes as arguments of their own.
    @njit(error_model="numpy", parallel=True)
    def demo(books, x):
        a, b = books
        for i in prange(x.shape[0]):
            a[i] = 1.0
            b[i] = x[i]

    a, b = np.zeros(3), np.zeros(3)
    demo((a, b), np.ones(3))
    assert _unpacked_writes(demo.py_func) == ["a", "b"]  # the check sees them
    parallel = {k: f for k, f in _kernels().items() if f.targetoptions.get("parallel")}
    assert len(parallel) >= 30
    bad = {k: _unpacked_writes(f.py_func) for k, f in parallel.items()}
    assert {k: v for k, v in bad.items() if v} == {}
