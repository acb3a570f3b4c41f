"""Keyword objects of a deck, each with the block it came from.

The fields are read by ``ansys-dyna-core`` (PyAnsys' keyword classes,
generated from the LS-DYNA manual: fixed, long and free-format fields,
``*PARAMETER`` references; docs/dependencies.md says why this library).
A keyword it cannot read (a card cut short, a field that is not a number,
an undefined parameter) is an error naming the file, line and keyword.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

from .scan import FRAME, Block, KeywordError, scan


@dataclass
class Keyword:
    """A block and what ansys-dyna-core made of it (``None`` for the blocks
    this package reads itself: :data:`OWN`)."""

    block: Block
    obj: object

    @property
    def name(self) -> str:
        return self.block.name


@dataclass
class KeywordDeck:
    """A keyword deck read: its title, its keywords in order and whether
    long fields are the default."""

    path: Path
    title: str
    keywords: list[Keyword]
    long: bool


#: Blocks read here, not by the library (:mod:`.scan` says why)
OWN = ("ELEMENT_SPH", "ELEMENT_SOLID", "SET_NODE_LIST", "SET_NODE_LIST_TITLE",
       "SET_PART_LIST", "SET_PART_LIST_TITLE")


#: Keywords whose first card (an ID and heading) exists only with the ``_ID``
#: option, but which ansys-dyna-core 0.12.1 reads always: it took a plain
#: block's first data card for the ID card (found by this project's tests).
#: A plain block is given to it with a blank first card.
OPTION_ID = ("DEFINE_ADAPTIVE_SOLID_TO_SPH",)


def _library_text(b: Block) -> str:
    """A block's text as the library reads it (:data:`OPTION_ID`)."""
    if b.name in OPTION_ID:
        return "\n".join([b.title, ""] + [s for _, s in b.lines])
    return b.text()


def read_keyword_deck(path) -> KeywordDeck:
    """Read ``path`` and its includes. Raises :class:`KeywordError`."""
    try:
        from ansys.dyna.core import Deck
    except ImportError:  # pragma: no cover - the extra is part of the test install
        raise KeywordError("reading LS-DYNA keyword decks needs the package "
                           "ansys-dyna-core: pip install 'sphdyn[lsdyna]'") from None
    path = Path(path)
    blocks, long = scan(path)
    title = next((b.lines[0][1].strip() for b in blocks
                  if b.name == "TITLE" and b.lines), path.stem)
    body = [b for b in blocks if f"*{b.name}" not in FRAME]
    given = [b for b in body if b.name not in OWN]
    text = "\n".join(["*KEYWORD LONG=Y" if long else "*KEYWORD"]
                     + [_library_text(b) for b in given] + ["*END"])
    deck = Deck()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        deck.loads(text)
    objs = list(deck.all_keywords)
    if len(objs) != len(given):
        raise KeywordError(f"{path}: {len(given)} keywords found but "
                           f"ansys-dyna-core read {len(objs)}: a keyword line it "
                           "could not place (check the lines starting with '*')")
    starts, at = [], 2  # the line of each block in the text given to the library
    for b in given:
        starts.append(at)
        at += 1 + len(b.lines) + (b.name in OPTION_ID)
    messages = [str(w.message) for w in caught]
    for b, obj, start in zip(given, objs, starts):
        if isinstance(obj, str):
            why = next((m for m in messages if m.endswith(f"on line {start}")), "")
            why = why.split(" for keyword beginning")[0]
            raise KeywordError(f"{b.where()}: cannot be read"
                               + (f" ({why})" if why else "")
                               + ": check its cards against the keyword manual "
                                 "(a card cut short, a field that is not a number, "
                                 "an undefined &parameter)")
    it = iter(objs)
    keywords = [Keyword(b, None if b.name in OWN else next(it)) for b in body]
    return KeywordDeck(path, title, keywords, long)
