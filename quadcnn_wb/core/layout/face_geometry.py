"""Plane geometry of a face's outline that the splits of odd faces (subdivide.py, peel.py)
share: whether a straight cut stays inside, which side of a line a point lies on, and
angles measured counter-clockwise."""

from __future__ import annotations

import math

import numpy as np

from .partition_types import inside_polygon


def ccw_angle(u, v) -> float:
    """Counter-clockwise angle from u to v, in [0, 2 pi)."""
    return math.atan2(u[0] * v[1] - u[1] * v[0], float(u @ v)) % (2 * math.pi)


def segment_inside(outline, a, b) -> bool:
    """The segment a-b lies inside the closed outline: its middle inside, and no outline
    segment away from its ends crosses it."""
    if not inside_polygon(outline, (a + b) / 2):
        return False
    p, q = outline, np.roll(outline, -1, axis=0)
    tol = 1e-9 * np.hypot(*(b - a))
    away = (_distance_to_ends(p, a, b) > tol) & (_distance_to_ends(q, a, b) > tol)
    d1, d2 = side_of(a, b, p), side_of(a, b, q)
    d3, d4 = side_of(p, q, a), side_of(p, q, b)
    hits = (d1 * d2 < 0) & (d3 * d4 < 0) & away
    return not hits.any()


def side_of(u, v, w) -> np.ndarray:
    """Twice the signed area of (u, v, w), row by row: which side of u-v w lies on."""
    return (v[..., 0] - u[..., 0]) * (w[..., 1] - u[..., 1]) \
        - (v[..., 1] - u[..., 1]) * (w[..., 0] - u[..., 0])


def _distance_to_ends(points, a, b) -> np.ndarray:
    return np.minimum(np.hypot(*(points - a).T), np.hypot(*(points - b).T))
