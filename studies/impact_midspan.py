"""The first milliseconds of the quick Lozano 2.5 m impact at mid-span
(docs/validation.md, "What the impact does to the beam in its first
millisecond"): the CSCM state of the beam's mid-span particle column
(x = 585 mm, y = 45 mm, every depth) every 50 us.

Prints, per record, the brittle/ductile damage at depths 5-95 mm, and for
the particles at z = 45, 85 and 95 mm the undamaged (viscoplastic) stress
[MPa], the total strain [per mille] and the rate factor; at the end the
mean mid-span deflection of the particles below mid-height [mm].

    PYTHONPATH=src python studies/impact_midspan.py [T_END_S] [--set KEY=VALUE ...]

(default T_END_S 0.004; e.g. --set material.concrete.recovery=10). About
2 minutes on 2 cores per millisecond.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DECK = ROOT / "validation" / "cases" / "lozano2017_dropweight.toml"
QUICK = ["body.beam.dx=0.01"] + [f"mesh.bar_{b}.line.element_length=0.01"
                                 for b in ("b1", "b2", "t1", "t2")]
EVERY = 5e-5
DEPTHS = (0.005, 0.025, 0.045, 0.065, 0.085, 0.095)
COMPONENTS = ("xx", "yy", "zz", "xy", "yz", "xz")


def main(argv: list[str]) -> None:
    from sphdyn.build import build_stepper
    from sphdyn.deck import load_deck

    t_end = float(argv[0]) if argv and not argv[0].startswith("--") else 0.004
    sets = [a for k, a in enumerate(argv) if k > 0 and argv[k - 1] == "--set"]
    st = build_stepper(load_deck(DECK, overrides=QUICK + sets))
    p = st.part("sph").kin
    names = list(p.hist_names)
    col = {n: names.index(n) for n in names}
    column = np.flatnonzero((p.mat == 0) & (np.abs(p.x0[:, 0] - 0.585) < 1e-4)
                            & (np.abs(p.x0[:, 1] - 0.045) < 1e-4))
    at = {z: column[np.argmin(np.abs(p.x0[column, 2] - z))] for z in DEPTHS}
    below = (p.mat == 0) & (np.abs(p.x0[:, 0] - 0.59) < 0.011) & (p.x0[:, 2] < 0.05)
    nxt = 0.0
    while st.t < t_end:
        st.step()
        if st.t < nxt:
            continue
        nxt += EVERY
        h = p.hist
        dmg = " ".join(f"{h[i, col['damage_brittle']]:.2f}/{h[i, col['damage_ductile']]:.2f}"
                       for i in at.values())
        print(f"t {1e3 * st.t:.2f} ms  db/dd at z = 5..95 mm: {dmg}")
        for z in (0.045, 0.085, 0.095):
            i = at[z]
            s = [h[i, col[f"sigvp_{c}"]] / 1e6 for c in COMPONENTS]
            e = [h[i, col[f"strain_{c}"]] * 1e3 for c in COMPONENTS]
            print(f"    z {1e3 * z:.0f} mm: svp [MPa] {np.round(s, 1)}  eps [1e-3] "
                  f"{np.round(e, 2)}  rate factor {h[i, col['rate_factor']]:.2f}")
    print(f"mid-span deflection below mid-height at {1e3 * st.t:.2f} ms: "
          f"{-1e3 * (p.x[below, 2] - p.x0[below, 2]).mean():.2f} mm")


if __name__ == "__main__":
    main(sys.argv[1:])
