#!/bin/sh
# Colliding rubber rings (Gray et al. 2001; thesis Figs. 3.3 and 3.4) with
# the three discretisations side by side: plain updated-Lagrangian SPH,
# updated-Lagrangian with artificial stress, total-Lagrangian with contact.
# Usage (from the repository root): sh docs/figures/make_rings_figures.sh
# About 15 min on 2 cores (3 runs of 17,608 particles to 11 ms).
set -e
OUT=${OUT:-out}
for deck in rings_gray2001 rings_gray2001_artificial_stress rings_gray2001_total_lagrangian; do
  sphdyn run examples/$deck.toml --out "$OUT/$deck" --set run.t_end=11e-3 \
      --set output.every=2.5e-4 -q || true   # a blown-up run keeps its frames
done
sphdyn plot "$OUT/rings_gray2001" "$OUT/rings_gray2001_artificial_stress" \
    "$OUT/rings_gray2001_total_lagrangian" --snapshots von_mises \
    --times 0.5ms,1.25ms,4ms,8ms,11ms --vmax 1.2e6 \
    --out docs/figures/rings_variants_von_mises.png
