"""The picture a validation case shows beside its numbers: the target's
mid-section at the run's end, coloured by damage, with the measured depth,
crater and scab drawn over it (the experiment's outline on the model)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..io.frames import list_frames
from ..io.hdf5 import read_frame, read_frame_meshes


def section_figure(run: Path, case, rows, path: Path, data_dir: Path) -> None:
    """Mid-section (a layer one element thick at y >= 0) of the mesh
    ``case.mesh`` in the last frame of ``run``, damage in colour, particles
    as dots, and the measured ``dop``, ``crater`` and ``scab`` of ``rows``
    (the compared rows, with their scatter) as black lines, sphdyn's as red ones; written to
    ``path`` (PNG). Nothing is drawn for a case without a mesh."""
    if not getattr(case, "mesh", ""):
        return
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .cases import block_spacing, resolved_deck

    deck = resolved_deck(run)
    block = next(m for m in deck["mesh"] if m["name"] == case.mesh)["block"]
    _, hy, _ = block_spacing(deck, case.mesh)
    face, back = block["hi"][2], block["lo"][2]
    last = list_frames(run)[-1]
    mesh = read_frame_meshes(last)[case.mesh]
    c = np.asarray(mesh.points)[mesh.cells].mean(axis=1)
    keep = (c[:, 1] >= 0.0) & (c[:, 1] < hy)
    t, _, fields, _ = read_frame(last)
    x = fields["position"]
    slab = (x[:, 1] >= 0.0) & (x[:, 1] < hy)
    fig, ax = plt.subplots(figsize=(7.5, 5.2), layout="constrained")
    art = ax.scatter(1e3 * c[keep, 0], 1e3 * c[keep, 2], c=mesh.cell_data["damage"][keep],
                     s=6, marker="s", cmap="viridis", vmin=0, vmax=1)
    ax.scatter(1e3 * x[slab, 0], 1e3 * x[slab, 2], s=2, c="0.3", label="particles")
    fig.colorbar(art, ax=ax, label="damage")
    by_key = {r["key"]: r for r in rows}
    for key, z in (("crater", face), ("scab", back)):
        if key in by_key:
            r = by_key[key]
            ax.plot([-r["measured"] / 2, r["measured"] / 2], [1e3 * z] * 2, "k-", lw=3,
                    label=f"{key} measured")
            ax.plot([-r["sphdyn"] / 2, r["sphdyn"] / 2], [1e3 * z + 1.5] * 2, "r-", lw=2,
                    label=f"{key} sphdyn")
    if "dop" in by_key:
        r = by_key["dop"]
        ax.axhspan(1e3 * face - r["high"], 1e3 * face - r["low"], color="0.85", zorder=0,
                   label="depth, measured scatter")
        ax.axhline(1e3 * face - r["measured"], color="k", ls="--", label="depth measured")
        ax.axhline(1e3 * face - r["sphdyn"], color="r", ls=":", label="depth sphdyn")
    ax.set(xlabel="x [mm]", ylabel="z [mm]", aspect="equal",
           title=f"{case.name}: mid-section at {1e6 * t:.0f} us")
    ax.legend(fontsize=7, loc="lower right")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _peer(rows, key: str) -> float | None:
    """Another code's answer for ``key`` among the compared ``rows`` (None
    where its authors published none)."""
    return next((r["peer"] for r in rows if r["key"] == key and r.get("peer") is not None),
                None)


def deflection_figure(run: Path, case, rows, path: Path, data_dir: Path, *,
                      history: str, drop_height: str) -> None:
    """Mid-span deflection against time after the contact's start: sphdyn's
    (the ``midspan`` probe; the start from the ``rod`` mesh's contact force)
    as a line, every beam dropped on from ``drop_height`` [m, as written in
    the data] in the data file ``history`` as points (their printed maxima
    filled), and another code's largest deflection and its time where the
    compared ``rows`` carry one (a star); written to ``path`` (PNG)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from . import data
    from .measures import deflection_history

    t, u = deflection_history(run, "midspan", "rod")
    table = data.read(data_dir / history)
    fig, ax = plt.subplots(figsize=(7.5, 4.6), layout="constrained")
    beams = sorted({r["beam_id"] for r in table.rows if r["drop_height_m"] == drop_height})
    for k, beam in enumerate(beams):
        pts = [r for r in table.rows if r["beam_id"] == beam]
        tt = [data.number(r, "t_ms") for r in pts]
        uu = [data.number(r, "u_mm") for r in pts]
        ax.plot(tt, uu, "o", ms=4, mfc="none", color=f"C{k % 10}",
                label=f"{beam} (measured)")
        peak = [i for i, r in enumerate(pts) if r["is_max"] == "1"]
        ax.plot([tt[i] for i in peak], [uu[i] for i in peak], "o", ms=5, color=f"C{k % 10}")
    ax.plot(1e3 * t, 1e3 * u, "k-", lw=2, label="sphdyn")
    u_peer, t_peer = _peer(rows, "umax"), _peer(rows, "t_umax")
    if u_peer is not None and t_peer is not None:
        ax.plot([t_peer], [u_peer], "*", ms=11, color="0.35",
                label="largest, the authors' LS-DYNA")
    ax.set(xlabel="time after impact [ms]", ylabel="mid-span deflection [mm]",
           title=f"{case.name}: mid-span deflection")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def load_figure(run: Path, case, rows, path: Path, data_dir: Path, *, loader: str,
                midspan: str, window: float) -> None:
    """Load against mid-span deflection of a quasi-static test
    (:func:`~sphdyn.validation.measures.load_deflection`: the ``loader``
    mesh's contact force averaged over ``window`` [s]), with the measured
    peak load's scatter of ``rows`` as a band and another code's peak load
    (dotted) where the rows carry one; written to ``path`` (PNG)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .measures import load_deflection

    u, f = load_deflection(run, loader, midspan, window)
    fig, ax = plt.subplots(figsize=(7.5, 4.6), layout="constrained")
    for r in rows:
        if r["key"] == "peak_load":
            ax.axhspan(r["low"], r["high"], color="0.85", label="peak load, measured scatter")
            ax.axhline(r["measured"], color="k", ls="--", label="peak load, measured mean")
    peer = _peer(rows, "peak_load")
    if peer is not None:
        ax.axhline(peer, color="0.35", ls=":", label="peak load, the authors' LS-DYNA")
    ax.plot(1e3 * u, 1e-3 * f, "k-", lw=2, label=f"sphdyn (load averaged over "
                                                  f"{1e3 * window:g} ms)")
    ax.set(xlabel="mid-span deflection [mm]", ylabel="load [kN]",
           title=f"{case.name}: load against deflection")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.savefig(path, dpi=110)
    plt.close(fig)
