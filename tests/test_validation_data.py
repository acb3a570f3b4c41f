"""The measured data of validation/data/ (issue 53): every file names its
source and where it was read, parses as CSV, and is listed in SOURCES.md.

A file without its provenance lines, or with a row of another width than its
header, fails here: the comparisons (docs/validation.md) may use only values
whose source a reader can look up.
"""

import csv
import io
from pathlib import Path

import pytest

DATA = Path(__file__).parents[1] / "validation" / "data"
FILES = sorted(DATA.glob("*.csv"))


def test_there_is_data_and_a_sources_page():
    assert len(FILES) >= 5 and (DATA / "SOURCES.md").is_file()
    assert (Path(__file__).parents[1] / "docs" / "validation.md").is_file()


@pytest.mark.parametrize("path", FILES, ids=[p.stem for p in FILES])
def test_each_file_names_its_source_and_parses(path):
    lines = path.read_text(encoding="utf-8").splitlines()
    comments = [ln for ln in lines if ln.startswith("#")]
    body = [ln for ln in lines if ln.strip() and not ln.startswith("#")]
    heads = " ".join(c.split(":", 1)[0].lower() for c in comments)
    assert "dataset" in heads and "source" in heads, f"{path.name}: no dataset/source line"
    assert "read" in heads, f"{path.name}: no line saying where the values were read"
    rows = list(csv.reader(io.StringIO("\n".join(body))))
    assert len(rows) >= 2, f"{path.name}: a header and at least one row"
    widths = {len(r) for r in rows}
    assert widths == {len(rows[0])}, f"{path.name}: rows of widths {sorted(widths)}"
    assert path.name in (DATA / "SOURCES.md").read_text(encoding="utf-8")


def test_nothing_outside_mat159_is_on_by_default_and_decks_mark_it_calibrated():
    """sphdyn's rate scaling of the CSCM damage thresholds is not MAT_159's:
    off by default (it was on), and every example deck that switches it on
    says CALIBRATED on that line (docs/validation.md, "Calibrated
    parameters", gives the default's result beside the deck's)."""
    import re

    from sphdyn.materials.cscm.schema import CscmParams

    assert CscmParams.model_fields["rate_thresholds"].default is False
    examples = Path(__file__).parents[1] / "examples"
    marked = 0
    for deck in sorted(examples.glob("*.toml")):
        for line in deck.read_text(encoding="utf-8").splitlines():
            if re.match(r"\s*rate_thresholds\s*=\s*true", line):
                assert "CALIBRATED" in line, f"{deck.name}: {line}"
                marked += 1
    assert marked == 10
    page = (Path(__file__).parents[1] / "docs" / "validation.md").read_text(encoding="utf-8")
    assert "## Calibrated parameters" in page and "studies/calibration_disc.py" in page


def test_validation_decks_mark_every_departure_from_the_mat159_fits():
    """A validation deck that replaces one of MAT_159's fitted parameters
    (a name of sphdyn.materials.cscm.PARAM_NAMES, or K, G) says why within
    the comment block above it: MEASURED (a property of the tested
    material, with its source) or CALIBRATED (chosen to match a result),
    as docs/validation.md, "Calibrated parameters", describes. The
    Lozano decks' fracture energies are such a block."""
    import re

    from sphdyn.materials.cscm import PARAM_NAMES

    cases = Path(__file__).parents[1] / "validation" / "cases"
    names = set(PARAM_NAMES) | {"K", "G"}
    replaced = 0
    for deck in sorted(cases.glob("*.toml")):
        lines = deck.read_text(encoding="utf-8").splitlines()
        in_cscm = False
        for i, line in enumerate(lines):
            if line.lstrip().startswith("["):
                in_cscm = False  # a new table; a CSCM material says so below
            if re.match(r'\s*model\s*=\s*"cscm"', line):
                in_cscm = True
            m = re.match(r"\s*(\w+)\s*=", line)
            if not (in_cscm and m and m.group(1) in names):
                continue
            replaced += 1
            j = i
            while j > 0 and re.match(r"\s*\w+\s*=", lines[j - 1]) and \
                    re.match(r"\s*(\w+)", lines[j - 1]).group(1) in names:
                j -= 1  # a block of replaced parameters shares one comment
            above = []
            while j > 0 and lines[j - 1].lstrip().startswith("#"):
                above.append(lines[j - 1])
                j -= 1
            text = " ".join(above) + line
            assert "MEASURED" in text or "CALIBRATED" in text, f"{deck.name}: {line}"
    assert replaced >= 6  # the two Lozano decks' GFT, GFS, GFC
