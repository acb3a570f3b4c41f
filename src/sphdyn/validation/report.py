"""Compare a case's measured numbers with its run, and write the table.

Verdict bands (docs/validation.md, "How to read the table"): **agrees** when
sphdyn's value lies inside the measured scatter or within 10 % of the
measured value; **fair** within 25 %; **poor** beyond. The 10 % band is of
the order of the scatter of repeated shots in the data (Leppänen's eight
shots: depth 52-57 mm, crater 74-93 mm); the 25 % band is a project choice
for "right in kind, not in number". An estimate (no scatter) is judged by
the same bands and marked as an estimate. Where the experiment's authors
published another code's answer on the same test (``Reference.peer``), the
table shows it and its difference from the measurement beside sphdyn's.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from .cases import UNITS, Reference

AGREES_PCT, FAIR_PCT = 10.0, 25.0
BEGIN, END = "<!-- sphdyn validate: begin -->", "<!-- sphdyn validate: end -->"


def difference_pct(value: float, measured: float) -> float:
    """How far ``value`` is from ``measured``, in per cent of it (NaN for 0)."""
    return 100.0 * (value / measured - 1.0) if measured else float("nan")


def verdict(ref: Reference, value: float) -> tuple[float, str]:
    """(difference [%] of ``value`` from ``ref.value``, verdict word);
    ``value`` in the reference's display unit."""
    diff = difference_pct(value, ref.value)
    if ref.low <= value <= ref.high or abs(diff) <= AGREES_PCT:
        word = "agrees"
    elif abs(diff) <= FAIR_PCT:
        word = "fair"
    else:
        word = "poor"
    return diff, word


def compare(refs: list[Reference], measured_si: dict[str, float]) -> list[dict]:
    """One row per reference: measured, sphdyn, difference, verdict."""
    rows = []
    for ref in refs:
        value = measured_si[ref.key] * UNITS[ref.unit]
        diff, word = verdict(ref, value)
        rows.append({"key": ref.key, "quantity": f"{ref.label} [{ref.unit}]",
                     "measured": ref.value, "low": ref.low, "high": ref.high,
                     "kind": ref.kind, "source": ref.source, "scatter": ref.scatter,
                     "sphdyn": value, "difference_pct": diff, "verdict": word,
                     "peer": ref.peer, "peer_label": ref.peer_label})
    return rows


def _g(x: float) -> str:
    return f"{x:.3g}"


def table_markdown(results: list[dict]) -> str:
    """The validation table of ``results`` (one dict per case run)."""
    lines = ["| case | quantity | measured (scatter) | sphdyn | difference | verdict "
             "| another code (difference) |",
             "|---|---|---|---|---|---|---|"]
    for res in results:
        if res["status"] != "completed":
            lines.append(f"| {res['case']} | run {res['status']} | | | | not compared | |")
            continue
        for row in res["rows"]:
            ref = _g(row["measured"])
            if row["kind"] == "estimate":
                ref = f"{ref} (estimate)"
            elif row["low"] != row["high"]:
                ref = f"{ref} ({_g(row['low'])}-{_g(row['high'])})"
            peer = row.get("peer")
            other = "" if peer is None else \
                f"{_g(peer)} ({difference_pct(peer, row['measured']):+.0f} %)"
            lines.append(f"| {res['case']} | {row['quantity']} | {ref} | {_g(row['sphdyn'])} | "
                         f"{row['difference_pct']:+.0f} % | {row['verdict']} | {other} |")
    return "\n".join(lines)


def sources_markdown(results: list[dict]) -> str:
    """Where each reference value comes from, one bullet per case."""
    out = []
    for res in results:
        seen, peers = [], []  # each text once, in the rows' order
        for row in res.get("rows", []):
            text = row["source"] + (f"; scatter: {row['scatter']}" if row["scatter"] else "")
            if text not in seen:
                seen.append(text)
            if row.get("peer") is not None and row["peer_label"] not in peers:
                peers.append(row["peer_label"])
        if seen:
            other = f"; another code: {' / '.join(peers)}" if peers else ""
            out.append(f"* **{res['case']}** ({res['title']}): " + " / ".join(seen)
                       + other + ".")
    return "\n".join(out)


def write_results(results: list[dict], out: Path) -> None:
    """``out/results.json`` and ``out/validation.md`` (the table and sources)."""
    out.mkdir(parents=True, exist_ok=True)
    (out / "results.json").write_text(json.dumps(results, indent=1) + "\n")
    (out / "validation.md").write_text(table_markdown(results) + "\n\n"
                                       + sources_markdown(results) + "\n")


def update_page(page: Path, block: str) -> None:
    """Replace the text between :data:`BEGIN` and :data:`END` in ``page``
    (``ValueError`` if the markers are missing)."""
    text = page.read_text(encoding="utf-8")
    pattern = re.compile(re.escape(BEGIN) + ".*?" + re.escape(END), re.S)
    if not pattern.search(text):
        raise ValueError(f"{page}: no '{BEGIN}' ... '{END}' block to fill")
    page.write_text(pattern.sub(lambda _: f"{BEGIN}\n{block}\n{END}", text), encoding="utf-8")
