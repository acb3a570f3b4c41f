"""The keyword files as blocks: where each keyword starts, ``*INCLUDE``s
followed, and the ``*ELEMENT_SPH`` rows.

The fields of every other keyword are read by ``ansys-dyna-core``
(:mod:`sphdyn.lsdyna.reader`); this module only cuts the text into keyword
blocks (a line starting with ``*`` starts one; ``$`` lines are comments), so
that each keyword can be named with its file and line in a message, follows
``*INCLUDE`` files in place (searched beside the including file, then beside
the main file), refuses a main file without ``*END``, and reads the rows of
``*ELEMENT_SPH``, of which ansys-dyna-core 0.12 keeps only the first (its
class holds one card, not a table), of ``*ELEMENT_SOLID``, whose long-format
rows it misreads, and of ``*SET_NODE_LIST`` and ``*SET_PART_LIST``, whose
comma-separated lines it cuts short (found by this project's tests,
tests/test_lsdyna_import.py).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

#: Keywords that frame a file rather than define anything
FRAME = ("*KEYWORD", "*END", "*TITLE")


class KeywordError(ValueError):
    """A keyword deck that cannot be read: the message names the file, the
    line and the keyword."""


@dataclass
class Block:
    """One keyword: its title line (``*MAT_ELASTIC_TITLE``), the file and the
    1-based line it starts on, and its data lines with their line numbers
    (comments removed)."""

    title: str
    file: Path
    line: int
    lines: list[tuple[int, str]] = field(default_factory=list)

    def text(self) -> str:
        """The keyword as text: its title line and data lines."""
        return "\n".join([self.title] + [s for _, s in self.lines])

    @property
    def name(self) -> str:
        """The keyword without options or format suffix: ``*NODE +`` ->
        ``NODE``."""
        return self.title.split()[0].lstrip("*").rstrip("+-%").upper()

    def where(self) -> str:
        return f"{self.file}, line {self.line}: *{self.name}"

    def long(self, deck_long: bool) -> bool:
        """Whether the block's fields are long (20 characters): the deck's
        ``*KEYWORD LONG=Y`` or the keyword's ``+`` suffix."""
        return deck_long or self.title.split()[0].endswith("+")


def _blocks(path: Path) -> tuple[list[Block], bool, bool]:
    """The blocks of one file, whether it has ``*END`` and whether its
    ``*KEYWORD`` line asks for long fields (``LONG=Y``)."""
    try:
        text = path.read_text(errors="replace")
    except OSError as e:
        raise KeywordError(f"{path}: cannot be read ({e.strerror})") from None
    blocks: list[Block] = []
    has_end = long = False
    for k, line in enumerate(text.splitlines(), start=1):
        if line.startswith("$"):
            continue
        if line.startswith("*"):
            word = line.split()[0].upper() if line.split() else "*"
            if word == "*END":
                has_end = True
                break
            if word == "*KEYWORD" and "LONG=Y" in line.upper().replace(" ", ""):
                long = True
            blocks.append(Block(line.rstrip(), path, k))
        elif blocks:
            blocks[-1].lines.append((k, line.rstrip("\n")))
        elif line.strip():
            raise KeywordError(f"{path}, line {k}: data before the first keyword "
                               f"({line.strip()[:40]!r})")
    return blocks, has_end, long


def scan(main: Path) -> tuple[list[Block], bool]:
    """All blocks of ``main`` with its ``*INCLUDE`` files inlined, in the
    order the solver reads them; ``True`` if the main file's ``*KEYWORD`` line
    sets long fields. Raises :class:`KeywordError` for a main file without
    ``*END``, a missing include file or an include cycle."""
    main = Path(main)
    blocks, has_end, long = _blocks(main)
    if not has_end:
        raise KeywordError(f"{main}: no *END (a keyword deck ends with a line *END; "
                           "without it the file may be cut short)")
    return _inline(blocks, main.parent, [main.resolve()]), long


def _inline(blocks: list[Block], home: Path, chain: list[Path]) -> list[Block]:
    out: list[Block] = []
    for b in blocks:
        if b.name != "INCLUDE":
            out.append(b)
            continue
        names = [s.strip() for _, s in b.lines if s.strip()]
        if not names:
            raise KeywordError(f"{b.where()}: no file name on the line after it")
        for name in names:
            found = next((d / name for d in (b.file.parent, home)
                          if (d / name).is_file()), None)
            if found is None:
                raise KeywordError(f"{b.where()}: the included file {name!r} is found "
                                   f"neither beside {b.file.name} nor in {home}")
            if found.resolve() in chain:
                raise KeywordError(f"{b.where()}: {name} includes itself (through "
                                   f"{' -> '.join(p.name for p in chain)})")
            inner, _, _ = _blocks(found)
            out.extend(_inline(inner, home, chain + [found.resolve()]))
    return out


def _fields(line: str, widths: tuple[int, ...]) -> list[str]:
    """The fields of a data line: comma-separated (free format) or fixed
    columns of ``widths``."""
    if "," in line:
        parts = [s.strip() for s in line.split(",")]
    else:
        parts, at = [], 0
        for w in widths:
            parts.append(line[at:at + w].strip())
            at += w
    return parts + [""] * (len(widths) - len(parts))


def sph_elements(block: Block, long: bool) -> list[tuple[int, int, float]]:
    """``(nid, pid, mass)`` of each row of an ``*ELEMENT_SPH`` block: fields
    NID, PID (I8) and MASS (E16), or I20/I20/E20 in long format
    (``*ELEMENT_SPH +`` or ``*KEYWORD LONG=Y``), or comma-separated. MASS
    blank or 0 is returned as 0.0 (the caller decides)."""
    widths = (20, 20, 20) if block.long(long) else (8, 8, 16)
    rows = []
    for k, line in block.lines:
        if not line.strip():
            continue
        nid, pid, mass = _fields(line, widths)[:3]
        try:
            rows.append((int(nid), int(pid), float(mass) if mass else 0.0))
        except ValueError:
            raise KeywordError(f"{block.file}, line {k}: *ELEMENT_SPH row "
                               f"{line.strip()!r} is not NID, PID, MASS (fields of "
                               f"{widths[0]}, {widths[1]} and {widths[2]} characters, or "
                               "comma-separated)") from None
    return rows


def id_list(block: Block, long: bool) -> tuple[int, list[int]]:
    """``(sid, ids)`` of a ``*SET_NODE_LIST`` or ``*SET_PART_LIST`` block: the
    first card's SID, then ids eight to a line in fields of 10 characters (20
    in long format) or comma-separated; blanks and zeros end nothing and are
    skipped. Read here because ansys-dyna-core 0.12 keeps only the first
    fields of a comma-separated line (found by this project's tests)."""
    width = 20 if block.long(long) else 10
    what = f"*{block.name}"
    cards = [(k, s) for k, s in block.lines if s.strip()]
    if "TITLE" in block.title.upper():
        cards = cards[1:]
    if not cards:
        raise KeywordError(f"{block.where()}: no card with the set's SID")
    k, first = cards[0]
    try:
        sid = int(_fields(first, (width,) * 5)[0])
    except ValueError:
        raise KeywordError(f"{block.file}, line {k}: {what}'s first field "
                           f"{first.strip()[:20]!r} is not the set's id") from None
    ids = []
    for k, line in cards[1:]:
        for text in _fields(line, (width,) * 8):
            if not text:
                continue
            try:
                n = int(text)
            except ValueError:
                raise KeywordError(f"{block.file}, line {k}: {text!r} is not an id "
                                   f"({what})") from None
            if n:
                ids.append(n)
    return sid, ids


def solid_elements(block: Block, long: bool) -> list[tuple[int, int, tuple[int, ...]]]:
    """``(eid, pid, (n1, ..., n8))`` of each row of an ``*ELEMENT_SOLID``
    block: fields of 8 characters (20 in long format) or comma-separated.
    Read here because ansys-dyna-core 0.12 misreads the long-format rows it
    writes itself (found by this project's tests)."""
    width = 20 if block.long(long) else 8
    rows = []
    for k, line in block.lines:
        if not line.strip():
            continue
        fields = _fields(line, (width,) * 10)[:10]
        try:
            ids = [int(f) for f in fields]
        except ValueError:
            raise KeywordError(f"{block.file}, line {k}: *ELEMENT_SOLID row "
                               f"{line.strip()[:60]!r} is not EID, PID and eight node "
                               f"ids (fields of {width} characters, or "
                               "comma-separated)") from None
        rows.append((ids[0], ids[1], tuple(ids[2:])))
    return rows
