"""Fuzzing the deck: mutated example decks end in status 0 or 2, never a traceback.

Every example deck is mutated deterministically (one mutation per case,
seeded by the case number; the mutations take turns, each on decks drawn
from the examples): a key deleted or renamed, a value of the wrong type or
unit, negative, zero, huge or not finite, a table emptied, a body
duplicated, nonsense text, a file reference to a missing file; and absurd
sizes, counts and factors: a number times 1e6, sph.h_factor or
support_scale of 1e6, mesh divisions of 1e9, dx of 1e-9 m, whole numbers
times 1e9, a domain box of 1e30 m, t_end of 1e30 s with output every
1e-30 s. Each mutated
deck goes through ``sphdyn check`` in-process: it must return 0, or 2 with a
one-paragraph message that names a field and a fix; no exception may escape.
A few accepted ones also run two steps.
"""

import math
import random
from pathlib import Path

import pytest
import tomli_w
import tomllib

from sphdyn.cli import main

EXAMPLES = sorted((Path(__file__).parent.parent / "examples").glob("*.toml"))
#: Every fuzzed deck may build at most this much (a mutation such as a
#: halved dx must not make the test build a model of gigabytes).
MEMORY_LIMIT = "150 MB"
N_CASES = 224


def _paths(node, prefix=()):
    """Every key path of a parsed TOML document: tables, lists and leaves."""
    if isinstance(node, dict):
        for key, value in node.items():
            yield prefix + (key,)
            yield from _paths(value, prefix + (key,))
    elif isinstance(node, list):
        for i, value in enumerate(node):
            if isinstance(value, (dict, list)):
                yield from _paths(value, prefix + (i,))


def _parent(doc, path):
    node = doc
    for key in path[:-1]:
        node = node[key]
    return node


def _leaves(doc, kinds):
    return [p for p in _paths(doc) if isinstance(_parent(doc, p)[p[-1]], kinds)]


def _set(doc, path, value):
    _parent(doc, path)[path[-1]] = value


def _delete(doc, rng):
    path = rng.choice(list(_paths(doc)))
    del _parent(doc, path)[path[-1]]


def _rename(doc, rng):
    path = rng.choice([p for p in _paths(doc) if isinstance(p[-1], str)])
    parent = _parent(doc, path)
    key = path[-1]
    new = rng.choice([key + "s", key[:-1], key.upper(), key.replace("_", "-") + "_"])
    parent[new if new != key else key + "x"] = parent.pop(key)


def _wrong_type(doc, rng):
    path = rng.choice(list(_paths(doc)))
    value = _parent(doc, path)[path[-1]]
    options = {dict: ["table?", 3, [1, 2]], list: [3, "list?", {"a": 1}],
               str: [5, True, [1, "a"]], bool: ["yes", 1.5], int: ["two", 2.5, [2]],
               float: ["0.5 parsecs?", False, {"x": 1}]}
    _set(doc, path, rng.choice(options.get(type(value), ["?"])))


def _wrong_unit(doc, rng):
    candidates = _leaves(doc, (str,)) or _leaves(doc, (int, float))
    path = rng.choice(candidates)
    _set(doc, path, rng.choice(["3 MPa", "12 kg", "5 m/s", "2 ms", "7 furlongs",
                                "4 mm/K", "1 GiB"]))


def _number(value_of):
    """A mutation that sets a numeric leaf (or a unit string's number) to ``value_of(x)``."""
    def mutate(doc, rng):
        candidates = _leaves(doc, (int, float, str))
        path = rng.choice(candidates)
        old = _parent(doc, path)[path[-1]]
        if isinstance(old, str):
            number, _, unit = old.partition(" ")
            try:
                x = float(number)
            except ValueError:
                x = 1.0
            new = value_of(x)
            _set(doc, path, f"{new:g} {unit}".strip() if isinstance(new, float)
                 and math.isfinite(new) else new)
        else:
            _set(doc, path, value_of(float(old)) if not isinstance(old, bool) else 0)
    return mutate


def _empty_table(doc, rng):
    path = rng.choice([p for p in _paths(doc)
                       if isinstance(_parent(doc, p)[p[-1]], (dict, list))])
    value = _parent(doc, path)[path[-1]]
    _set(doc, path, {} if isinstance(value, dict) else [])


def _duplicate_body(doc, rng):
    bodies = doc.get("body") or [{}]
    doc.setdefault("body", []).append(dict(rng.choice(bodies)))


def _nonsense(doc, rng):
    path = rng.choice(list(_paths(doc)))
    _set(doc, path, rng.choice(["\u2603 snow", "", " ", "NaN", "1e999 mm", "-0",
                                "mm 5", "${HOME}", "0x1F", "null"]))


def _missing_file(doc, rng):
    bodies = doc.get("body") or []
    if bodies and isinstance(bodies[0], dict):
        bodies[0]["mesostructure"] = {"photo": "no/such/section.png",
                                      "pixel_size": "0.1 mm"}
    else:
        doc["body"] = [{"mesostructure": {"photo": "missing.png"}}]


def _dimension(doc) -> int:
    run = doc.get("run")
    dim = run.get("dimension") if isinstance(run, dict) else None
    return dim if dim in (1, 2, 3) else 3


def _tables(doc, section) -> list:
    items = doc.get(section)
    return [t for t in items if isinstance(t, dict)] if isinstance(items, list) else []


def _sph_factor(key):
    """sph.<key> set to 1e6 (or 1e-9 for support_scale, every other case)."""
    def mutate(doc, rng):
        sph = doc.setdefault("sph", {}) if isinstance(doc.get("sph", {}), dict) else {}
        sph[key] = rng.choice([1e6, 1e-9]) if key == "support_scale" else 1e6
    return mutate


def _mesh_divisions(doc, rng):
    """A mesh's element count to 1e9 (block divisions, line divisions or
    element length, prism element size), or, without meshes, a body's dx."""
    meshes = _tables(doc, "mesh")
    if not meshes:
        return _tiny_dx(doc, rng)
    mesh = rng.choice(meshes)
    if isinstance(mesh.get("block"), dict):
        mesh["block"]["divisions"] = [10**9] * _dimension(doc)
    elif isinstance(mesh.get("line"), dict):
        line = mesh["line"]
        line.pop("element_length", None)
        line["divisions"] = 10**9
    elif isinstance(mesh.get("prism"), dict):
        mesh["prism"]["element_size"] = "1e-9 m"
    else:
        mesh["block"] = {"lo": [0] * _dimension(doc), "hi": [1] * _dimension(doc),
                         "divisions": [10**9] * _dimension(doc)}


def _tiny_dx(doc, rng):
    """A body's dx of 1e-9 m (or, without bodies, a mesh's divisions)."""
    bodies = _tables(doc, "body")
    if bodies:
        rng.choice(bodies)["dx"] = "1e-9 m"
    elif _tables(doc, "mesh"):
        _mesh_divisions(doc, rng)


def _huge_count(doc, rng):
    """A whole number (a count: divisions, octaves, repeat, history_every,
    particles_per_element, classes, seed ...) times 1e9."""
    paths = [p for p in _leaves(doc, (int,))
             if not isinstance(_parent(doc, p)[p[-1]], bool)]
    if not paths:
        return _number(lambda x: x * 1e9)(doc, rng)
    path = rng.choice(paths)
    _set(doc, path, max(abs(_parent(doc, path)[path[-1]]), 1) * 10**9)


def _huge_domain(doc, rng):
    """A [domain] box of 1e30 m on every side."""
    dim = _dimension(doc)
    domain = doc.setdefault("domain", {}) if isinstance(doc.get("domain", {}), dict) else {}
    domain["lo"] = [-1e30] * dim
    domain["hi"] = [1e30] * dim


def _endless_run(doc, rng):
    """t_end of 1e30 s with an output every 1e-30 s (or every step)."""
    if isinstance(doc.get("run"), dict):
        doc["run"]["t_end"] = 1e30
    output = doc.setdefault("output", {}) if isinstance(doc.get("output", {}), dict) else {}
    output["every"] = rng.choice([1e-30, "1e-30 s"])


MUTATIONS = {
    "delete": _delete, "rename": _rename, "wrong_type": _wrong_type,
    "wrong_unit": _wrong_unit, "negative": _number(lambda x: -abs(x) - 1.0),
    "zero": _number(lambda x: 0.0), "huge": _number(lambda x: 1e300),
    "tiny": _number(lambda x: 1e-300), "not_finite": _number(lambda x: math.inf),
    "empty_table": _empty_table, "duplicate_body": _duplicate_body,
    "nonsense": _nonsense, "missing_file": _missing_file,
    # absurd sizes, counts and factors (issue 57)
    "factor_1e6": _number(lambda x: x * 1e6), "h_factor_1e6": _sph_factor("h_factor"),
    "support_scale": _sph_factor("support_scale"), "divisions_1e9": _mesh_divisions,
    "dx_1e-9": _tiny_dx, "count_1e9": _huge_count, "domain_1e30": _huge_domain,
    "t_end_1e30": _endless_run,
}


def mutated_deck(case: int) -> tuple[str, dict]:
    """``(description, document)`` of fuzz case ``case`` (deterministic)."""
    rng = random.Random(20261124 + case)
    name = list(MUTATIONS)[case % len(MUTATIONS)]
    example = rng.choice(EXAMPLES)
    doc = tomllib.loads(example.read_text(encoding="utf-8"))
    MUTATIONS[name](doc, rng)
    if isinstance(doc.get("run"), dict):
        doc["run"]["memory_limit"] = MEMORY_LIMIT
    return f"{example.stem}:{name}", doc


def _write(doc, path: Path) -> bool:
    """Write the document; False if TOML cannot hold it (e.g. an empty key)."""
    try:
        path.write_text(tomli_w.dumps(doc), encoding="utf-8")
    except (TypeError, ValueError):
        return False
    return True


def _assert_one_paragraph(err: str, what: str):
    text = err.strip()
    assert text, f"{what}: status 2 without a message"
    assert "Traceback" not in text and "\n\n" not in text, f"{what}:\n{err}"
    assert "Fix:" in text or "error:" in text, f"{what}: no fix named:\n{err}"


@pytest.fixture(scope="module")
def checked(tmp_path_factory):
    """Every case through ``sphdyn check``: case -> (description, path, status)."""
    base = tmp_path_factory.mktemp("fuzz")
    results = {}
    for case in range(N_CASES):
        what, doc = mutated_deck(case)
        path = base / f"case_{case:03d}.toml"
        if not _write(doc, path):
            continue
        results[case] = (what, path, None)
    return base, results


def test_every_mutation_is_tried_on_several_decks():
    """Each mutation (the absurd sizes among them) gets N_CASES / 21 cases,
    at least 10, on at least 5 different examples."""
    tried, cases = {}, {}
    for case in range(N_CASES):
        what, _ = mutated_deck(case)
        deck, name = what.split(":")
        tried.setdefault(name, set()).add(deck)
        cases[name] = cases.get(name, 0) + 1
    assert set(tried) == set(MUTATIONS) and min(cases.values()) >= 10
    assert all(len(decks) >= 5 for decks in tried.values()), tried


def test_at_least_200_mutated_decks_end_in_0_or_2_with_one_paragraph(checked, capsys):
    _, results = checked
    assert len(results) >= 200
    statuses, failures = {}, []
    for case, (what, path, _) in sorted(results.items()):
        try:
            rc = main(["check", str(path)])
            err = capsys.readouterr().err
            assert rc in (0, 2), f"case {case} {what}: status {rc}\n{err}"
            if rc == 2:
                _assert_one_paragraph(err, f"case {case} {what}")
        except Exception as exc:  # noqa: BLE001 -- every failure listed at once
            failures.append(f"case {case} {what}: {type(exc).__name__}: {exc}")
            continue
        results[case] = (what, path, rc)
        statuses[rc] = statuses.get(rc, 0) + 1
    assert not failures, "\n".join(failures)
    assert statuses.get(2, 0) > 100  # most mutations are caught


def test_a_few_accepted_mutants_run_two_steps(checked, capsys):
    base, results = checked
    small = ("elastic_disc_bounce", "ucs_homogeneous", "two_boxes_close",
             "rings_gray2001", "rings_gray2001_artificial_stress",
             "rings_gray2001_total_lagrangian", "sod_shock_tube", "gurney_1d")
    runnable = [(case, what, path) for case, (what, path, rc) in sorted(results.items())
                if rc in (0, None) and what.split(":")[0] in small]
    ran = 0
    for case, what, path in runnable:
        if main(["check", str(path)]) != 0:
            continue
        rc = main(["run", str(path), "--out", str(base / f"run_{case:03d}"),
                   "--max-steps", "2", "-q"])
        err = capsys.readouterr().err
        assert rc in (0, 1), f"case {case} {what}: status {rc}\n{err}"
        ran += 1
        if ran == 10:
            break
    assert ran >= 5
