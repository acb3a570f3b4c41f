"""Post-processing: fragment counting, and contact forces averaged over a window.

A *fragment* is a connected component of the graph in which two particles
are linked when their distance is below a link length ``d_ij``. With
``d = 2 h`` (the cubic-spline support radius) two fragments no longer
interact through the SPH sums at all, i.e. the body has come apart
numerically or physically; a shorter link length (say 1.5 dx) also detects
cracks that are still within one support of each other.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

__all__ = ["fragment_labels", "count_fragments", "fragment_sizes", "window_mean_force"]


def fragment_labels(x, h_or_radius, body=None, mask=None) -> np.ndarray:
    """Fragment label of every particle.

    Particles ``i, j`` are linked when ``|x_i - x_j| < (d_i + d_j) / 2``
    (``d`` the link length) and, if ``body`` is given, ``body[i] ==
    body[j]``.

    Parameters
    ----------
    x : (N, k) positions [m], k = 2 or 3 (a 2D model stored as (N, 3) with
        z = 0 works as is).
    h_or_radius : float or (N,) link length [m] (e.g. ``2 * h`` or ``1.5 * dx``).
    body : (N,) int, optional; particles of different bodies are never linked.
    mask : (N,) bool, optional; particles with False (e.g. zero mass) get
        label -1 and are ignored.

    Returns
    -------
    (N,) int labels, 0..n_fragments-1 (consecutive), -1 for masked particles.
    """
    x = np.asarray(x, dtype=float)
    n = x.shape[0]
    d = np.broadcast_to(np.asarray(h_or_radius, dtype=float), (n,))
    keep = np.ones(n, bool) if mask is None else np.asarray(mask, bool)
    labels = np.full(n, -1, dtype=np.int64)
    sel = np.flatnonzero(keep)
    if sel.size == 0:
        return labels
    xs, ds = x[sel], d[sel]
    pairs = cKDTree(xs).query_pairs(float(ds.max()), output_type="ndarray")
    if pairs.size:
        i, j = pairs[:, 0], pairs[:, 1]
        r = np.linalg.norm(xs[i] - xs[j], axis=1)
        ok = r < 0.5 * (ds[i] + ds[j])
        if body is not None:
            b = np.asarray(body)[sel]
            ok &= b[i] == b[j]
        i, j = i[ok], j[ok]
    else:
        i = j = np.zeros(0, dtype=np.int64)
    graph = coo_matrix((np.ones(i.size, dtype=np.int8), (i, j)), shape=(sel.size,) * 2)
    _, lab = connected_components(graph, directed=False)
    labels[sel] = lab
    return labels


def count_fragments(x, h_or_radius, body=None, mask=None, min_size=1):
    """Number of fragments (connected components), in total or per body.

    Parameters
    ----------
    x, h_or_radius, body, mask : see :func:`fragment_labels`.
    min_size : int, fragments with fewer particles are not counted (e.g. to
        ignore single spalled particles).

    Returns
    -------
    int if ``body`` is None, else a dict ``{body index: fragment count}``
    over the body indices present.
    """
    labels = fragment_labels(x, h_or_radius, body, mask)
    sizes = fragment_sizes(labels)
    if body is None:
        return int((sizes >= min_size).sum())
    body = np.asarray(body)
    out = {}
    for b in np.unique(body[labels >= 0]):
        lab = np.unique(labels[(body == b) & (labels >= 0)])
        out[int(b)] = int((sizes[lab] >= min_size).sum())
    return out


def fragment_sizes(labels) -> np.ndarray:
    """Particle count of each fragment, indexed by label (-1 labels ignored)."""
    labels = np.asarray(labels)
    return np.bincount(labels[labels >= 0]) if (labels >= 0).any() else np.zeros(0, int)


def window_mean_force(time, impulse, window: float) -> np.ndarray:
    r"""Contact force averaged over the last ``window`` seconds, from the impulse.

    .. math:: \bar F(t) = \frac{I(t) - I(t - \tau)}{\tau},
              \qquad I(t) = \int_0^t F\,dt,

    the mean force over :math:`[t - \tau, t]` (a moving average; its
    maximum is the peak a load cell of response time :math:`\tau` would
    read). :math:`I` is the history column ``I_wall_<name>``, which the
    solver accumulates every step, so the average is exact however sparsely
    the history is recorded; :math:`I(t - \tau)` is linearly interpolated
    between records and taken as 0 before the first one (no contact before
    the run starts). A window of several steps smooths the spikes of the
    penalty spring when a few particles first touch the wall.

    Parameters
    ----------
    time : (K,) record times [s], increasing.
    impulse : (K,) cumulative normal impulse [N s] (N s/m in 2D) at ``time``.
    window : float, tau [s] > 0.

    Returns
    -------
    (K,) mean force [N] (N/m in 2D) over the window ending at each record.
    """
    if not window > 0:
        raise ValueError(f"window must be > 0 s, got {window}")
    time = np.asarray(time, dtype=float)
    impulse = np.asarray(impulse, dtype=float)
    before = np.interp(time - window, time, impulse, left=0.0)
    return (impulse - before) / window


def projected_max(x0, values, dx: float, axes: tuple[int, int] = (0, 2)) -> np.ndarray:
    """A view of a lattice body along its third axis: the largest of ``values``
    at each point of the plane of ``axes``, as an image.

    ``x0`` (N, 3) the particles' initial positions (cell centres of a lattice
    of spacing ``dx`` [m] from the origin, or element centres), ``values``
    (N,), ``axes`` (horizontal, vertical) of the image. Returns (nv, nh) with
    ``img[k, i]`` the largest value of the particles in cell
    ``(floor(x_h/dx), floor(x_v/dx)) = (i, k)``, NaN where none.
    """
    ih = np.floor(x0[:, axes[0]] / dx).astype(int)  # the centres are mid-cell: no ties
    iv = np.floor(x0[:, axes[1]] / dx).astype(int)
    img = np.full((iv.max() + 1, ih.max() + 1), np.nan)
    np.fmax.at(img, (iv, ih), values)
    return img


def side_view_max(x0, values, dx: float) -> np.ndarray:
    """The side view (x-z plane, the largest value over the width y) of
    :func:`projected_max` (the damage pictures of examples/igirder.py and
    dropweight.py)."""
    return projected_max(x0, values, dx, (0, 2))
