"""Study: the Forrestal target's cut faces: free, on rollers or non-reflecting (issue 53).

The case's target (validation/cases/forrestal1994_ogive.toml) is cut to
300 x 300 mm and 360 mm deep; the experiment's concrete went on to a 1.37 m
culvert, 0.76 m long. The case puts its four lateral faces and its back face
on a non-reflecting boundary (the tables :func:`cut_faces` writes). This runs
the case (its quick version unless ``--full``) with those faces

* ``--faces free``: free (the case before 2026-11-30);
* ``--faces rollers``: the four lateral faces' nodes held in their normal
  direction (`[[boundary]]` type "fixed" with one component), the back free;
* ``--faces non_reflecting``: as the case has them (Lysmer-Kuhlemeyer
  dashpots, `[[boundary]]` type "non_reflecting");

and prints the depth of penetration as `sphdyn validate` measures it, and
the eroded elements. Extra ``--set`` values pass on (e.g.
``material.concrete.erosion.effective_strain=0.5``). The numbers in
docs/validation.md (2026-11-30):

    python studies/forrestal_lateral_faces.py --out OUT --faces free
    python studies/forrestal_lateral_faces.py --out OUT --faces rollers
    python studies/forrestal_lateral_faces.py --out OUT2 --faces rollers \\
        --set material.concrete.erosion.effective_strain=0.5
    python studies/forrestal_lateral_faces.py --out OUT3 --faces non_reflecting
"""

from __future__ import annotations

import argparse
import csv
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def cut_faces(kind: str) -> str:
    """The deck tables that put the target's lateral faces on rollers, or its
    lateral and back faces on a non-reflecting boundary (``kind``; "free":
    none)."""
    out = ""
    if kind == "free":
        return out
    sides = [("side_x_lo", "x", -151, -149), ("side_x_hi", "x", 149, 151),
             ("side_y_lo", "y", -151, -149), ("side_y_hi", "y", 149, 151)]
    if kind == "non_reflecting":
        sides.append(("back", "z", -361, -359))
    whole = dict(zip("xyz", ((-151, 151), (-151, 151), (-361, 1))))  # the block, +-1 mm
    for name, axis, lo, hi in sides:
        box = [(lo, hi) if axis == a else whole[a] for a in "xyz"]
        box_lo = [f'"{b[0]} mm"' for b in box]
        box_hi = [f'"{b[1]} mm"' for b in box]
        held = (f'type = "fixed"\ncomponents = ["{axis}"]' if kind == "rollers"
                else 'type = "non_reflecting"')
        out += (f'\n[[set]]\nname = "{name}"\nmesh = "target"\nregion = {{ shape = "box", '
                f'lo = [{", ".join(box_lo)}], hi = [{", ".join(box_hi)}] }}\n'
                f'\n[[boundary]]\nset = "{name}"\n{held}\n')
    return out


def case_with_faces(text: str, kind: str) -> str:
    """The case's deck ``text`` with its cut faces' tables replaced by those of
    ``kind``; ValueError if the deck does not hold them as :func:`cut_faces`
    writes them."""
    ours = cut_faces("non_reflecting")
    if text.count(ours) != 1:
        raise ValueError("the case's deck does not hold the non-reflecting faces' "
                         "tables as cut_faces writes them")
    return text.replace(ours, cut_faces(kind))


def main(argv=None) -> int:
    from sphdyn.validation.cases import CASES
    from sphdyn.validation.measures import depth_of_penetration

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--set", action="append", default=[])
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--faces", choices=("free", "rollers", "non_reflecting"),
                    default="non_reflecting")
    ap.add_argument("--full", action="store_true",
                    help="the case at its full resolution (hours), not the quick one")
    args = ap.parse_args(argv)
    case = CASES["forrestal1994_ogive"]
    args.out.mkdir(parents=True, exist_ok=True)
    deck = args.out / f"forrestal_{args.faces}.toml"
    deck.write_text(case_with_faces((ROOT / case.deck).read_text(encoding="utf-8"),
                                    args.faces), encoding="utf-8")
    run = args.out / "run"
    cmd = [sys.executable, "-m", "sphdyn", "run", str(deck), "--out", str(run), "-q",
           "--threads", str(args.threads)]
    quick = () if args.full else case.quick
    for override in (*quick, *args.set):
        cmd += ["--set", override]
    subprocess.run(cmd, check=True)
    resolved = tomllib.loads((run / "deck.resolved.toml").read_text(encoding="utf-8"))
    dx = next(b for b in resolved["body"] if b["name"] == "projectile")["dx"]
    rows = list(csv.DictReader(open(run / "history.csv", encoding="utf-8")))
    print(f"depth of penetration {1e3 * depth_of_penetration(run, 'projectile', 0.0, dx):.1f} mm, "
          f"eroded elements {float(rows[-1]['eroded_target']):.0f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
