"""Where two boundary curves meet, computed exactly (no polyline approximation).

Used to refuse self-intersecting and mutually intersecting loops; nearly touching loops
that do not meet must pass, which a chord approximation of arcs could not guarantee.
"""

from __future__ import annotations

import math

import numpy as np

from .curves import Arc, Line, cross2


class Overlap(Exception):
    """The two curves share a stretch of positive length."""


def curve_intersections(c1, c2, eps: float) -> list[np.ndarray]:
    """Points where c1 and c2 meet (within ``eps``); raises Overlap for shared stretches."""
    if isinstance(c1, Line) and isinstance(c2, Line):
        return _line_line(c1, c2, eps)
    if isinstance(c1, Line):
        return _line_arc(c1, c2, eps)
    if isinstance(c2, Line):
        return _line_arc(c2, c1, eps)
    return _arc_arc(c1, c2, eps)


def _on_arc(arc: Arc, p, eps: float) -> bool:
    ang = math.atan2(p[1] - arc.center[1], p[0] - arc.center[0])
    return arc.contains_angle(ang, eps / arc.radius)


def _line_line(l1: Line, l2: Line, eps: float) -> list[np.ndarray]:
    a, d1 = l1.p0, l1.p1 - l1.p0
    c, d2 = l2.p0, l2.p1 - l2.p0
    n1, n2 = float(np.hypot(*d1)), float(np.hypot(*d2))
    denom = cross2(d1, d2)
    if abs(denom) <= 1e-12 * n1 * n2:
        if abs(cross2(d1, c - a)) / n1 > eps:
            return []  # parallel, apart
        s0 = float(np.dot(c - a, d1)) / n1**2
        s1 = float(np.dot(l2.p1 - a, d1)) / n1**2
        lo, hi = max(0.0, min(s0, s1)), min(1.0, max(s0, s1))
        if (hi - lo) * n1 > eps:
            raise Overlap
        if hi - lo >= -eps / n1:
            return [a + 0.5 * (lo + hi) * d1]
        return []
    t = cross2(c - a, d2) / denom
    u = cross2(c - a, d1) / denom
    if -eps / n1 <= t <= 1 + eps / n1 and -eps / n2 <= u <= 1 + eps / n2:
        return [a + t * d1]
    return []


def _line_arc(line: Line, arc: Arc, eps: float) -> list[np.ndarray]:
    a, d = line.p0, line.p1 - line.p0
    n = float(np.hypot(*d))
    u = d / n
    foot_t = float(np.dot(arc.center - a, u))
    foot = a + foot_t * u
    h = float(np.hypot(*(arc.center - foot)))
    if h > arc.radius + eps:
        return []
    half = math.sqrt(max(arc.radius**2 - h**2, 0.0))
    candidates = [foot] if half <= eps else [foot - half * u, foot + half * u]
    out = []
    for p in candidates:
        s = float(np.dot(p - a, u))
        if -eps <= s <= n + eps and _on_arc(arc, p, eps):
            out.append(p)
    return out


def _arc_arc(c1: Arc, c2: Arc, eps: float) -> list[np.ndarray]:
    delta = c2.center - c1.center
    d = float(np.hypot(*delta))
    r1, r2 = c1.radius, c2.radius
    if d <= eps and abs(r1 - r2) <= eps:
        return _same_circle(c1, c2, eps)
    if d > r1 + r2 + eps or d < abs(r1 - r2) - eps or d <= eps:
        return []
    along = (d * d + r1 * r1 - r2 * r2) / (2.0 * d)
    half = math.sqrt(max(r1 * r1 - along * along, 0.0))
    e = delta / d
    base = c1.center + along * e
    perp = np.array([-e[1], e[0]])
    candidates = [base] if half <= eps else [base + half * perp, base - half * perp]
    return [p for p in candidates if _on_arc(c1, p, eps) and _on_arc(c2, p, eps)]


def _same_circle(c1: Arc, c2: Arc, eps: float) -> list[np.ndarray]:
    """Two arcs of one circle: they overlap unless they meet at end points only."""
    if c1.is_full or c2.is_full:
        raise Overlap

    def strictly_inside(arc: Arc, p) -> bool:
        """On the arc and more than eps from both of its ends."""
        ang = math.atan2(p[1] - arc.center[1], p[0] - arc.center[0])
        rel = (ang - arc.a0) * (1.0 if arc.sweep > 0 else -1.0) % (2.0 * math.pi)
        margin = eps / arc.radius
        return margin < rel < abs(arc.sweep) - margin

    probes = [(c1, c2.p0), (c1, c2.p1), (c1, c2.midpoint()), (c2, c1.p0), (c2, c1.p1),
              (c2, c1.midpoint())]
    if any(strictly_inside(arc, p) for arc, p in probes):
        raise Overlap
    return [p for p in (c2.p0, c2.p1) if _on_arc(c1, p, eps)]
