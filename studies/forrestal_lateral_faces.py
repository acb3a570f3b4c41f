"""Study: the Forrestal quick target's lateral faces, free or on rollers (issue 53).

The case's target (validation/cases/forrestal1994_ogive.toml) is cut to
300 x 300 mm with free lateral faces; the experiment's concrete went on to a
1.37 m culvert. This runs the quick version (the case's quick overrides)
with the four lateral faces' nodes held in their normal direction
(`[[set]]` boxes and `[[boundary]]` type "fixed" with one component: rollers)
and prints the depth of penetration as `sphdyn validate` measures it, and
the eroded elements. Extra ``--set`` values pass on (e.g.
``material.concrete.erosion.effective_strain=0.5``). The numbers in
docs/validation.md (2026-11-30):

    python studies/forrestal_lateral_faces.py --out OUT
    python studies/forrestal_lateral_faces.py --out OUT2 \\
        --set material.concrete.erosion.effective_strain=0.5
"""

from __future__ import annotations

import argparse
import csv
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ROLLERS = ""
for name, axis, lo, hi in (("side_x_lo", "x", -151, -149), ("side_x_hi", "x", 149, 151),
                           ("side_y_lo", "y", -151, -149), ("side_y_hi", "y", 149, 151)):
    box_lo = [f'"{lo} mm"' if axis == "x" else '"-151 mm"',
              f'"{lo} mm"' if axis == "y" else '"-151 mm"', '"-361 mm"']
    box_hi = [f'"{hi} mm"' if axis == "x" else '"151 mm"',
              f'"{hi} mm"' if axis == "y" else '"151 mm"', '"1 mm"']
    ROLLERS += (f'\n[[set]]\nname = "{name}"\nmesh = "target"\nregion = {{ shape = "box", '
                f'lo = [{", ".join(box_lo)}], hi = [{", ".join(box_hi)}] }}\n'
                f'\n[[boundary]]\nset = "{name}"\ntype = "fixed"\ncomponents = ["{axis}"]\n')


def main(argv=None) -> int:
    from sphdyn.validation.cases import CASES
    from sphdyn.validation.measures import depth_of_penetration

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--set", action="append", default=[])
    ap.add_argument("--threads", type=int, default=1)
    args = ap.parse_args(argv)
    case = CASES["forrestal1994_ogive"]
    args.out.mkdir(parents=True, exist_ok=True)
    deck = args.out / "forrestal_rollers.toml"
    deck.write_text((ROOT / case.deck).read_text(encoding="utf-8") + ROLLERS, encoding="utf-8")
    run = args.out / "run"
    cmd = [sys.executable, "-m", "sphdyn", "run", str(deck), "--out", str(run), "-q",
           "--threads", str(args.threads)]
    for override in (*case.quick, *args.set):
        cmd += ["--set", override]
    subprocess.run(cmd, check=True)
    dx = float(next(o for o in case.quick if o.startswith("body.projectile.dx=")).split("=")[1])
    rows = list(csv.DictReader(open(run / "history.csv", encoding="utf-8")))
    print(f"depth of penetration {1e3 * depth_of_penetration(run, 'projectile', 0.0, dx):.1f} mm, "
          f"eroded elements {float(rows[-1]['eroded_target']):.0f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
