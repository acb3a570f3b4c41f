"""The code and docs/theory.md point at each other, and every pointer lands.

A module states its model in a few lines and names the section of
docs/theory.md that has the equations, their references and their tests; a
section's heading names the modules it covers. These tests fail when a
section is renamed under a pointer, or a module a section names does not
point back.
"""

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
THEORY = (ROOT / "docs" / "theory.md").read_text(encoding="utf-8")
HEADING = re.compile(r"^#{2,3} (.+?)(?: \((.*)\))?\s*$")
POINTER = re.compile(r"docs/theory\.md[,]? \(?[\"']([^\"']+)[\"']")


def _titles() -> list[str]:
    """Section titles and the bold leads of its paragraphs (``**Hourglass control**``)."""
    titles = [m.group(1) for m in map(HEADING.match, THEORY.splitlines()) if m]
    return titles + re.findall(r"\*\*([^*]+)\*\*", THEORY)


def _named_modules() -> dict[str, str]:
    """``{src path: section title}`` of the modules the headings name
    (``sphdyn/...py`` and, after one, file names in the same folder)."""
    named = {}
    for line in THEORY.splitlines():
        m = HEADING.match(line)
        if not m or not m.group(2):
            continue
        folder = None
        for ref in re.findall(r"`([^`]+)`", m.group(2)):
            if ref.startswith("sphdyn/") and ref.endswith(".py"):
                folder = str(Path(ref).parent)
                named.setdefault(f"src/{ref}", m.group(1))
            elif folder and "/" not in ref and ref.endswith(".py"):
                named.setdefault(f"src/{folder}/{ref}", m.group(1))
    return named


def test_every_pointer_to_theory_names_a_section_that_exists():
    titles = _titles()
    pointers = []
    for path in sorted((ROOT / "src" / "sphdyn").rglob("*.py")):
        for title in POINTER.findall(path.read_text(encoding="utf-8")):
            title = " ".join(w for w in title.split() if w != "#")  # across lines
            pointers.append(title)
            assert any(t.startswith(title) for t in titles), (path.name, title)
    assert len(pointers) > 40  # the pattern finds them


def test_every_module_a_section_names_points_back_to_it():
    named = _named_modules()
    assert len(named) > 25
    for path, title in named.items():
        source = (ROOT / path).read_text(encoding="utf-8")
        doc = ast.get_docstring(ast.parse(source)) or ""
        assert "docs/theory.md" in doc, (path, title)
