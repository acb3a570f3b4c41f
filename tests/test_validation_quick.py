"""The quick validation cases (``sphdyn validate --quick``) as regression of
their compared numbers (issue 53).

Each quick case runs (leppanen2004_fragment about 1 minute on 2 cores,
forrestal1994_ogive about 3.5, the two lozano2017_dropweight cases about 4
and 5, the two meshed
lozano2017_dropweight_fem cases about 2 and 2.5 on one core, lozano2017_static
about 6) and its compared
numbers must stay within the tolerance of the values stored in
tests/data/validation_quick.json, which ``python tests/test_validation_quick.py
--store [RUNS_DIR [CASE ...]]`` rewrites after a deliberate change (say why in
the commit; the runs go to RUNS_DIR/a and RUNS_DIR/b, and completed ones
there are measured again, not rerun; with CASEs only their entries).

The tolerance of each number is stored beside it and comes from the same
evidence as the example regression's (docs/testing.md, "The regression
tolerances"): the case rerun with its striking velocity (the static test:
the concrete's density) moved by one ulp
(``--store`` does both runs); the difference between the two is how far
round-off alone moves the number on one machine, and a processor that
rounds differently moves it about as far. The tolerance is ``SAFETY`` times
that difference, and at least the measurement's own reading resolution
(``FLOOR``: half an element for a crater or depth read off a mesh, one
history interval for a time), so a case whose round-off moves nothing is
not held bit for bit where the measurement itself is coarser.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]
STORE = ROOT / "tests" / "data" / "validation_quick.json"
SAFETY = 10.0  # as the example regression's (docs/testing.md)
#: the reading resolution of each quantity in its display unit: half the
#: quick fragment target's 4 mm elements (crater, depth; the Forrestal depth,
#: read off the projectile's particles, moves by 4.6 % under a one-ulp change
#: of its velocity, so its stored spread sets it); for a time, 0.02 ms (the
#: quick beam's history records come every 20 steps of 0.6 us, 0.012 ms);
#: 1 % of a deflection and of a load (REL_FLOOR; the load averaged over 1 ms
#: windows moves by 1-2 % from window to window on its plateau)
FLOOR = {"dop": 2.0, "crater": 2.0, "t_umax": 0.02}
REL_FLOOR = {"umax": 0.01, "peak_load": 0.01}
#: the perturbation: the impactor's velocity override (or an input that moves
#: every step) moved by one ulp
PERTURB = {
    "leppanen2004_fragment": "body.fragment.velocity.2=-1879.0000000000002",
    "forrestal1994_ogive": "body.projectile.velocity.2=-277.00000000000006",
    "lozano2017_dropweight_2.5m": "mesh.rod.velocity.2=-6.900000000000001",
    "lozano2017_dropweight_5.0m": "mesh.rod.velocity.2=-9.800000000000002",
    "lozano2017_dropweight_fem_2.5m": "mesh.rod.velocity.2=-6.900000000000001",
    "lozano2017_dropweight_fem_5.0m": "mesh.rod.velocity.2=-9.800000000000002",
    # the loader's prescribed velocity moved by one ulp moves its nodes by
    # less than their positions' ulp, so nothing changes: the concrete's
    # density instead
    "lozano2017_static": "material.concrete.density=2425.0000000000005",
}


def _floor(key: str, value: float) -> float:
    return REL_FLOOR[key] * abs(value) if key in REL_FLOOR else FLOOR[key]


def _run(names, out: Path, perturb: bool = False, reuse: bool = False):
    """Run quick cases into ``out`` (with the one-ulp perturbation if
    ``perturb``); {case: {key: value}}."""
    from dataclasses import replace

    from sphdyn.validation.cases import CASES
    from sphdyn.validation.runner import run_case

    results = {}
    for name in names:
        case = CASES[name]
        if perturb:
            case = replace(case, quick=case.quick + (PERTURB[name],))
        res = run_case(case, ROOT, out, quick=True, threads=None, reuse=reuse)
        assert res["status"] == "completed", (name, res.get("diagnosis"))
        results[name] = {row["key"]: row["sphdyn"] for row in res["rows"]}
    return results


def store(runs: Path, names=None) -> None:
    """Run each quick case (or those of ``names``) and its one-ulp perturbed
    twin into ``runs`` (completed runs there are measured again, not rerun);
    write their values and tolerances to :data:`STORE`, keeping the other
    cases' entries."""
    from sphdyn.validation.cases import CASES

    names = list(CASES) if not names else list(names)
    base = _run(names, runs / "a", reuse=True)
    moved = _run(names, runs / "b", perturb=True, reuse=True)
    table = json.loads(STORE.read_text()) if STORE.is_file() else {}
    table = {k: v for k, v in table.items() if k in CASES}
    for name in names:
        table[name] = {}
        for key, value in base[name].items():
            spread = abs(moved[name][key] - value)
            table[name][key] = {"value": value, "perturbed": moved[name][key],
                                "tolerance": max(SAFETY * spread, _floor(key, value))}
    STORE.write_text(json.dumps(table, indent=1, sort_keys=True) + "\n")
    print(json.dumps(table, indent=1))


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(json.loads(STORE.read_text()))
                         if STORE.is_file() else [])
def test_quick_case_holds_its_numbers(name, tmp_path):
    stored = json.loads(STORE.read_text())[name]
    got = _run([name], tmp_path)[name]
    for key, entry in stored.items():
        assert math.isfinite(got[key])
        assert abs(got[key] - entry["value"]) <= entry["tolerance"], \
            f"{name} {key}: {got[key]:.4g}, stored {entry['value']:.4g} +- {entry['tolerance']:.3g}"


def test_every_case_has_stored_quick_numbers():
    from sphdyn.validation.cases import CASES

    stored = json.loads(STORE.read_text())
    assert sorted(stored) == sorted(CASES)
    for name, entries in stored.items():
        keys = {r.key for r in CASES[name].references(ROOT / "validation" / "data")}
        assert set(entries) == keys, name
        for e in entries.values():
            assert e["tolerance"] > 0 and math.isfinite(e["value"])


if __name__ == "__main__":
    # python tests/test_validation_quick.py --store [RUNS_DIR [CASE ...]]
    if "--store" in sys.argv:
        rest = sys.argv[sys.argv.index("--store") + 1:]
        store(Path(rest[0]) if rest else ROOT / "out" / "validation_quick_store", rest[1:])
