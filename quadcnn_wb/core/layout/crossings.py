"""Where polylines cross one another: the events of the T-mesh and the arrangement's
crossing vertices, found once, with arc-length positions on both lines."""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree


def cumulative_length(points: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])


def crossings(lines, h: float, tol: float, end_clearance: float = 0.5, ends=None,
              shared_ends_only: bool = False) -> list:
    """Proper crossings ((i, s_i), (j, s_j), xy) between different polylines.

    A crossing within ``end_clearance`` element sizes of an end of either line is where
    lines meet at a shared end point (a singular point they both leave), not a crossing.
    ``ends`` (per line, the points that count as its ends) defaults to both end points.
    With ``shared_ends_only`` the crossing must be near an end of both lines to be left
    out: a line passing close by another's foot on the boundary does cross it.
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
    if ends is None:
        ends = [(pts[0], pts[-1]) for pts in lines]
    ends = {k: tuple(e) for k, e in enumerate(ends)}
    for pi, pj, tt, uu in zip(i[hit], j[hit], t[hit], u[hit]):
        xy = a[pi] + tt * (b[pi] - a[pi])
        near_i = any(np.hypot(*(xy - e)) < end_clearance * h for e in ends[owner[pi]])
        near_j = any(np.hypot(*(xy - e)) < end_clearance * h for e in ends[owner[pj]])
        if (near_i and near_j) if shared_ends_only else (near_i or near_j):
            continue
        si = s0[pi] + tt * np.hypot(*(b[pi] - a[pi]))
        sj = s0[pj] + uu * np.hypot(*(b[pj] - a[pj]))
        out.append(((int(owner[pi]), float(si)), (int(owner[pj]), float(sj)), xy))
    # In the order of the lines and positions, not of the k-d tree's pairs.
    out.sort(key=lambda c: (c[0][0], c[0][1], c[1][0]))
    return out
