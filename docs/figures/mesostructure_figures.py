"""Regenerate the figures of docs/mesostructure.md.

Usage (from the repository root, ~1 minute on 2 threads):
    NUMBA_NUM_THREADS=2 python docs/figures/mesostructure_figures.py
Writes docs/figures/mesostructure_{rounded,crushed,fuller,photo}.png and
prints the statistics quoted in the document.
"""

import importlib.util
from pathlib import Path

from sphdyn.heterogeneity.mesostructure import (fuller_grading,
                                                generate_phase_grid,
                                                phase_statistics,
                                                save_phase_slices)
from sphdyn.heterogeneity.photo import (save_photo_comparison,
                                        segment_aggregate,
                                        structure_from_photo)

HERE = Path(__file__).parent
ROOT = HERE.parent.parent


def main():
    dx = 0.5e-3
    shape = (96, 96, 96)
    kw = dict(aggregate_fraction=0.45, itz_thickness=dx, seed=1)
    cases = {
        "rounded": dict(max_aggregate_size=12e-3, aggregate_shape="rounded"),
        "crushed": dict(max_aggregate_size=12e-3, aggregate_shape="crushed"),
        "fuller": dict(max_aggregate_size=16e-3, aggregate_shape="crushed",
                       grading=fuller_grading(16e-3, 4e-3)),
    }
    for name, c in cases.items():
        g = generate_phase_grid(shape, dx, **kw, **c)
        st = phase_statistics(g, dx)
        print(f"{name}: {st.summary()}")
        save_phase_slices(g, HERE / f"mesostructure_{name}.png", dx,
                          title=f"{name}: aggregate 0.45, D_max "
                                f"{c['max_aggregate_size'] * 1e3:.0f} mm, "
                                f"ITZ {dx * 1e3:.1f} mm")
    spec = importlib.util.spec_from_file_location(
        "msi", ROOT / "tests" / "data" / "make_section_image.py")
    msi = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(msi)
    grey, truth = msi.synthetic_section(shape=(400, 400), fraction=0.35,
                                        seed=1)
    res = structure_from_photo(grey, pixel_size=0.1e-3,
                               grid_shape=(80, 80, 80), dx=0.2e-3,
                               itz_thickness=0.2e-3, seed=1)
    print(f"synthetic photo, true fraction {truth.mean():.4f}")
    print(res.summary())
    save_photo_comparison(res, grey, segment_aggregate(grey),
                          HERE / "mesostructure_photo.png")


if __name__ == "__main__":
    main()
