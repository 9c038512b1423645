"""Where polylines cross one another: the events of the T-mesh and the arrangement's
crossing vertices, found once, with arc-length positions on both lines."""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree


def cumulative_length(points: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])


def point_at(points: np.ndarray, cum: np.ndarray, s: float) -> np.ndarray:
    """The polyline's point at arc length ``s`` (``cum``: its cumulative_length)."""
    # Clamped with min and max: np.clip on a scalar cost a partition of 300 blocks 0.2 s.
    k = min(max(int(np.searchsorted(cum, s, side="right")) - 1, 0), len(points) - 2)
    f = (s - cum[k]) / max(cum[k + 1] - cum[k], 1e-300)
    return points[k] + min(max(f, 0.0), 1.0) * (points[k + 1] - points[k])


def resampled(points: np.ndarray, n: int) -> np.ndarray:
    """``n`` points at equal arc length along the polyline, its ends included."""
    cum = cumulative_length(points)
    return np.array([point_at(points, cum, s) for s in np.linspace(0.0, cum[-1], n)])


def end_places(line) -> list:
    """(point, places) at both ends of a streamline: the singular point or corner it leaves
    or reaches, or ("line", j) when it ends on line j."""
    out = []
    for where, point in ((line.start, line.points[0]), (line.end, line.points[-1])):
        if where.kind == "singularity":
            out.append((point, {("s", where.index)}))
        elif where.kind == "corner":
            out.append((point, {("c", where.index)}))
        elif where.kind == "streamline":
            out.append((point, {("line", where.index)}))
        else:
            out.append((point, set()))
    return out


def crossings(lines, h: float, tol: float, ends, end_clearance: float = 0.5) -> list:
    """Proper crossings ((i, s_i), (j, s_j), xy) between different polylines.

    ``ends[k]`` lists (point, places) of line k's ends (see end_places).  Where two lines
    leave or reach the same singular point or corner, or one ends on the other, they meet
    there without crossing: a crossing within ``end_clearance`` element sizes of such a
    shared end is left out.  Any other crossing counts, however near an end it lies (a
    line passing close by another's foot on the boundary does cross it).
    """
    seg_a, seg_b, owner, s0 = [], [], [], []
    for k, pts in enumerate(lines):
        seg_a.append(pts[:-1])
        seg_b.append(pts[1:])
        owner.append(np.full(len(pts) - 1, k))
        s0.append(cumulative_length(pts)[:-1])
    if not seg_a:
        return []
    a, b = np.concatenate(seg_a), np.concatenate(seg_b)
    owner, s0 = np.concatenate(owner), np.concatenate(s0)
    mid = 0.5 * (a + b)
    half = 0.5 * np.hypot(*(b - a).T)
    radius = 2 * float(half.max()) + tol
    pairs = cKDTree(mid).query_pairs(radius, output_type="ndarray")
    if not len(pairs):
        return []
    pairs = pairs[owner[pairs[:, 0]] != owner[pairs[:, 1]]]
    i, j = pairs[:, 0], pairs[:, 1]
    d1, d2 = b[i] - a[i], b[j] - a[j]
    den = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    w = a[j] - a[i]
    scale = np.hypot(*d1.T) * np.hypot(*d2.T)
    ok = np.abs(den) > 1e-12 * np.maximum(scale, 1e-300)  # parallel: no proper crossing
    t = np.where(ok, (w[:, 0] * d2[:, 1] - w[:, 1] * d2[:, 0]) / np.where(ok, den, 1), -1)
    u = np.where(ok, (w[:, 0] * d1[:, 1] - w[:, 1] * d1[:, 0]) / np.where(ok, den, 1), -1)
    hit = ok & (t >= 0) & (t < 1) & (u >= 0) & (u < 1)
    out = []
    reach = end_clearance * h
    for pi, pj, tt, uu in zip(i[hit], j[hit], t[hit], u[hit]):
        xy = a[pi] + tt * (b[pi] - a[pi])
        li, lj = int(owner[pi]), int(owner[pj])
        near_i = set().union(*([places for point, places in ends[li]
                                if np.hypot(*(xy - point)) < reach] or [set()]))
        near_j = set().union(*([places for point, places in ends[lj]
                                if np.hypot(*(xy - point)) < reach] or [set()]))
        if ("line", lj) in near_i or ("line", li) in near_j or near_i & near_j:
            continue
        si = s0[pi] + tt * np.hypot(*(b[pi] - a[pi]))
        sj = s0[pj] + uu * np.hypot(*(b[pj] - a[pj]))
        out.append(((int(owner[pi]), float(si)), (int(owner[pj]), float(sj)), xy))
    # In the order of the lines and positions, not of the k-d tree's pairs.
    out.sort(key=lambda c: (c[0][0], c[0][1], c[1][0]))
    return out
