"""The mutation script (tools/mutation.py) stays usable: every mutant's snippet
is found exactly once in today's source and its tests exist. No mutant is run."""

import importlib.util
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _load():
    """tools/mutation.py as a module (tools/ is not a package)."""
    spec = importlib.util.spec_from_file_location("sphdyn_mutation",
                                                  ROOT / "tools" / "mutation.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # dataclasses look their module up there
    spec.loader.exec_module(mod)
    return mod


mutation = _load()


@pytest.mark.parametrize("mutant", mutation.MUTANTS, ids=lambda m: m.name)
def test_snippet_found_exactly_once(mutant):
    text = (ROOT / "src" / mutant.path).read_text(encoding="utf-8")
    assert text.count(mutant.old) == 1, mutant.old
    assert mutant.new != mutant.old


@pytest.mark.parametrize("mutant", mutation.MUTANTS, ids=lambda m: m.name)
def test_named_tests_exist(mutant):
    # node id "tests/file.py::[Class::]test_name[params]": the file exists and
    # defines the test (and the class) by that name
    assert mutant.tests
    for node in mutant.tests:
        file, *names = node.split("::")
        text = (ROOT / file).read_text(encoding="utf-8")
        assert names, node
        *classes, func = names
        func = func.split("[")[0]
        for cls in classes:
            assert re.search(rf"^class {cls}\b", text, re.M), node
        assert re.search(rf"^\s*def {func}\(", text, re.M), node


def test_the_list_covers_the_core_and_the_issue_items():
    # at least the 13 kinds of the mutation check of issue 14: the core
    # (kernels, neighbours, J2, CSCM, checkpoints) and items 1 to 6
    areas = {m.area for m in mutation.MUTANTS}
    core = {"kernels", "neighbours", "J2", "CSCM", "checkpoints"}
    items = {f"issue 14.{k}" for k in range(1, 7)}
    assert core | items <= areas
    assert len(mutation.MUTANTS) >= 13
    assert len({m.name for m in mutation.MUTANTS}) == len(mutation.MUTANTS)
    assert mutation.check_mutants() == []


def test_a_snippet_not_found_exactly_once_is_refused(tmp_path):
    (tmp_path / "m.py").write_text("a = 1\nb = 2\nb = 2\n")
    ok = mutation.Mutant("ok", "x", "m.py", "a = 1", "a = 3", ("t",), "")
    mutation.apply_mutant(ok, tmp_path)
    assert (tmp_path / "m.py").read_text() == "a = 3\nb = 2\nb = 2\n"
    for old in ("a = 1", "b = 2"):  # now absent; twice
        bad = mutation.Mutant("bad", "x", "m.py", old, "c = 0", ("t",), "")
        with pytest.raises(mutation.MutantRefused, match="exactly once"):
            mutation.apply_mutant(bad, tmp_path)
        assert mutation.check_mutants([bad], tmp_path)
    assert (tmp_path / "m.py").read_text() == "a = 3\nb = 2\nb = 2\n"


def test_verdicts():
    assert mutation.judge("failed") == mutation.judge("timeout") == "caught"
    assert mutation.judge("passed") == "survived"
    assert mutation.judge("error: pytest exit 4").startswith("error")
