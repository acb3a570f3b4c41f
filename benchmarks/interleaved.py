"""Best step time of several steppers stepped in turns (one process).

A shared machine's slow moments then hit every model alike; the best of
``repeat`` rounds is kept per model. Used by the benchmark scripts here.
"""

from __future__ import annotations

import time


def best_step_times(models: dict, steps: int, repeat: int) -> dict[str, float]:
    """Seconds per step of each stepper in ``models`` (name -> stepper), the
    best of ``repeat`` rounds of ``steps`` steps, the models taking turns."""
    best = {k: float("inf") for k in models}
    for _ in range(repeat):
        for name, st in models.items():
            t0 = time.perf_counter()
            for _ in range(steps):
                st.step()
            best[name] = min(best[name], (time.perf_counter() - t0) / steps)
    return best
