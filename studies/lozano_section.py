"""Plane-section beam theory for the static test of the Lozano & Makdesi
beams (docs/validation.md, "The static test against beam theory"): the
mid-span load P = 4 M / L of a simply supported span L under a central load,
M from a moment-curvature analysis of the deck's section
(``sphdyn.validation.estimates.rc_section_moment``: EN 1992-1-1's
parabola-rectangle concrete at the deck's mean strength, no concrete in
tension, the bars by the measured f0.2, fu and ultimate strain).

Prints the load at the first yield of the bottom bars, at the code's
crushing strain of the top fibre (eps_cu2 = 3.5 per mille), with the
bottom bars at the strain sphdyn's static run reaches at mid-span, and the
upper bound of the theory (a compression zone that never crushes, the bars
hardened to their ultimate strain). Reads the bars, section and materials
from validation/cases/lozano2017_static.toml. A second.

    PYTHONPATH=src python studies/lozano_section.py
"""

from __future__ import annotations

import math
from pathlib import Path

from scipy.optimize import brentq

ROOT = Path(__file__).resolve().parents[1]
DECK = ROOT / "validation" / "cases" / "lozano2017_static.toml"
SPAN = 1.0  # m, between the rollers (lozano2017_dropweight_rc_beams.csv header)
STEEL_ULTIMATE_STRAIN = 0.108  # K500C-T, Table 7.6 (same header)
SPHDYN_BAR_STRAIN = 0.035  # bottom bars' strain at mid-span in the static run


def section(deck):
    """(width, height, fc, bars, steel) of the deck's beam, SI units."""
    beam = next(b for b in deck.body if b.name == "beam")
    lo, hi = beam.geometry.lo, beam.geometry.hi
    width, height = hi[1] - lo[1], hi[2] - lo[2]
    mats = {m.name: m for m in deck.material}
    bars, steel = [], None
    for mesh in deck.mesh:
        if not mesh.name.startswith("bar_"):
            continue
        z = mesh.line.start[2]
        bars.append((hi[2] - z, math.pi * mesh.section.diameter ** 2 / 4))
        m = mats[mesh.material]
        fu = m.yield_stress + m.hardening_modulus * (STEEL_ULTIMATE_STRAIN - m.yield_stress / m.E)
        steel = dict(E=m.E, fy=m.yield_stress, fu=fu, eps_u=STEEL_ULTIMATE_STRAIN)
    return width, height, mats[beam.material].fc, bars, steel


def main() -> None:
    from sphdyn.deck import load_deck
    from sphdyn.validation.estimates import rc_section_moment

    b, h, fc, bars, steel = section(load_deck(DECK))
    d = max(depth for depth, _ in bars)
    load = lambda k: 4.0 * rc_section_moment(k, b, h, fc, bars, steel)[0] / SPAN

    def at(strain_of, target):
        """Curvature at which strain_of(curvature, c) reaches target."""
        f = lambda k: strain_of(k, rc_section_moment(k, b, h, fc, bars, steel)[1]) - target
        return brentq(f, 1e-6, 10.0, xtol=1e-12)

    bottom = lambda k, c: k * (d - c)
    top = lambda k, c: k * c
    eps_y = steel["fy"] / steel["E"]
    rows = [
        ("first yield of the bottom bars", load(at(bottom, eps_y))),
        ("top fibre at eps_cu2 = 3.5 per mille (EN 1992-1-1)", load(at(top, 3.5e-3))),
        # beyond eps_cu2 the concrete is held at fc: no crushing
        (f"bottom bars at {1e3 * SPHDYN_BAR_STRAIN:.0f} per mille, no crushing",
         load(at(bottom, SPHDYN_BAR_STRAIN))),
        ("bottom bars at their ultimate strain, no crushing (upper bound)",
         load(at(bottom, STEEL_ULTIMATE_STRAIN))),
    ]
    print(f"section {1e3 * b:.0f} x {1e3 * h:.0f} mm, fc {fc / 1e6:.1f} MPa, bars at "
          + ", ".join(f"{1e3 * y:.0f} mm ({1e6 * a:.1f} mm2)" for y, a in bars)
          + f", steel fy {steel['fy'] / 1e6:.0f} fu {steel['fu'] / 1e6:.0f} MPa, span {SPAN} m")
    for label, p in rows:
        print(f"{label:66s} P = {p / 1e3:5.2f} kN")


if __name__ == "__main__":
    main()
