"""Exact boundary curves: straight lines and circular arcs (a circle is a full arc).

Every later stage places points on the boundary through these classes, so that a node on
an arc or circle lies on the true curve rather than on a chord of it.  Parameters run
from 0 to 1 along each curve in its direction of travel.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

TWO_PI = 2.0 * math.pi


def cross2(a, b) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def wrap_angle(angle: float) -> float:
    """Angle in [0, 2*pi)."""
    wrapped = math.fmod(angle, TWO_PI)
    return wrapped + TWO_PI if wrapped < 0.0 else wrapped


@dataclass(frozen=True)
class Line:
    p0: np.ndarray
    p1: np.ndarray

    kind = "line"

    @property
    def length(self) -> float:
        return float(np.hypot(*(self.p1 - self.p0)))

    def point(self, t):
        t = np.asarray(t, dtype=float)
        if t.ndim == 0:
            if t == 0.0:
                return self.p0.copy()
            if t == 1.0:
                return self.p1.copy()
            return self.p0 + float(t) * (self.p1 - self.p0)
        pts = self.p0[None, :] + t[:, None] * (self.p1 - self.p0)[None, :]
        pts[t == 0.0] = self.p0
        pts[t == 1.0] = self.p1
        return pts

    def tangent(self, t=0.0):
        d = (self.p1 - self.p0) / self.length
        t = np.asarray(t, dtype=float)
        return d.copy() if t.ndim == 0 else np.repeat(d[None, :], len(t), axis=0)

    def project(self, p) -> float:
        d = self.p1 - self.p0
        t = float(np.dot(np.asarray(p, dtype=float) - self.p0, d) / np.dot(d, d))
        return min(1.0, max(0.0, t))

    def reversed(self) -> Line:
        return Line(self.p1, self.p0)

    def with_start(self, p0) -> Line:
        return Line(np.asarray(p0, dtype=float), self.p1)

    def sample(self, n: int) -> np.ndarray:
        return self.point(np.linspace(0.0, 1.0, n))

    def signed_area_term(self, origin=(0.0, 0.0)) -> float:
        """This curve's share of 0.5 * closed-integral (x dy - y dx), about ``origin``."""
        return 0.5 * cross2(self.p0 - origin, self.p1 - origin)

    def to_json(self) -> dict:
        return {"line": [self.p0.tolist(), self.p1.tolist()]}


@dataclass(frozen=True)
class Arc:
    """Circular arc from angle ``a0`` over the signed ``sweep`` (|sweep| = 2*pi: a circle).

    The end points are stored, not recomputed, so that consecutive curves of a loop meet
    exactly where the input said they meet.
    """

    center: np.ndarray
    radius: float
    a0: float
    sweep: float
    p0: np.ndarray
    p1: np.ndarray

    @property
    def kind(self) -> str:
        return "circle" if self.is_full else "arc"

    @property
    def is_full(self) -> bool:
        return abs(abs(self.sweep) - TWO_PI) < 1e-12

    @property
    def length(self) -> float:
        return abs(self.sweep) * self.radius

    @classmethod
    def through(cls, p0, pm, p1) -> Arc:
        """Arc from p0 through pm to p1; the caller has checked the points are not collinear."""
        p0, pm, p1 = (np.asarray(p, dtype=float) for p in (p0, pm, p1))
        center = circumcenter(p0, pm, p1)
        radius = float(np.mean([np.hypot(*(p - center)) for p in (p0, pm, p1)]))
        a0 = math.atan2(p0[1] - center[1], p0[0] - center[0])
        a1 = math.atan2(p1[1] - center[1], p1[0] - center[0])
        if cross2(pm - p0, p1 - pm) > 0.0:  # turning left: counter-clockwise about the centre
            sweep = wrap_angle(a1 - a0)
        else:
            sweep = -wrap_angle(a0 - a1)
        return cls(center, radius, a0, sweep, p0, p1)

    @classmethod
    def circle(cls, center, radius: float, counter_clockwise: bool = True) -> Arc:
        center = np.asarray(center, dtype=float)
        start = center + np.array([radius, 0.0])
        return cls(center, float(radius), 0.0, TWO_PI if counter_clockwise else -TWO_PI,
                   start, start.copy())

    def _angles(self, t):
        return self.a0 + np.asarray(t, dtype=float) * self.sweep

    def point(self, t):
        t = np.asarray(t, dtype=float)
        ang = self._angles(t)
        pts = self.center + self.radius * np.stack([np.cos(ang), np.sin(ang)], axis=-1)
        if t.ndim == 0:
            if t == 0.0:
                return self.p0.copy()
            if t == 1.0:
                return self.p1.copy()
            return pts
        pts[t == 0.0] = self.p0
        pts[t == 1.0] = self.p1
        return pts

    def tangent(self, t=0.0):
        ang = self._angles(t)
        s = 1.0 if self.sweep > 0 else -1.0
        return s * np.stack([-np.sin(ang), np.cos(ang)], axis=-1)

    def contains_angle(self, angle: float, tol: float = 0.0) -> bool:
        """Whether the direction ``angle`` (seen from the centre) lies on the arc."""
        if self.is_full:
            return True
        rel = wrap_angle((angle - self.a0) * (1.0 if self.sweep > 0 else -1.0))
        return rel <= abs(self.sweep) + tol or rel >= TWO_PI - tol

    def project(self, p) -> float:
        p = np.asarray(p, dtype=float)
        ang = math.atan2(p[1] - self.center[1], p[0] - self.center[0])
        rel = wrap_angle((ang - self.a0) * (1.0 if self.sweep > 0 else -1.0))
        span = abs(self.sweep)
        if self.is_full:
            return rel / span
        if rel <= span:
            return rel / span
        # Beyond the end: pick whichever end point is nearer along the circle.
        return 1.0 if rel - span < TWO_PI - rel else 0.0

    def reversed(self) -> Arc:
        return Arc(self.center, self.radius, self.a0 + self.sweep, -self.sweep, self.p1, self.p0)

    def with_start(self, p0) -> Arc:
        p0 = np.asarray(p0, dtype=float)
        return Arc(self.center, self.radius, self.a0, self.sweep, p0,
                   p0.copy() if self.is_full else self.p1)

    def sample(self, n: int) -> np.ndarray:
        return self.point(np.linspace(0.0, 1.0, n))

    def midpoint(self) -> np.ndarray:
        return self.point(0.5)

    def signed_area_term(self, origin=(0.0, 0.0)) -> float:
        """This curve's share of 0.5 * closed-integral (x dy - y dx) about ``origin``,
        exactly."""
        return 0.5 * (cross2(self.center - origin, self.p1 - self.p0)
                      + self.radius**2 * self.sweep)

    def to_json(self) -> dict:
        if self.is_full:
            return {"circle": {"center": self.center.tolist(), "radius": self.radius}}
        return {"arc": [self.p0.tolist(), self.midpoint().tolist(), self.p1.tolist()]}


def circumcenter(a, b, c) -> np.ndarray:
    ax, ay = b - a
    bx, by = c - a
    d = 2.0 * (ax * by - ay * bx)
    ux = (by * (ax * ax + ay * ay) - ay * (bx * bx + by * by)) / d
    uy = (ax * (bx * bx + by * by) - bx * (ax * ax + ay * ay)) / d
    return a + np.array([ux, uy])


def curve_bbox(curve) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned box, exact for both kinds (arcs include their axis extremes)."""
    pts = [curve.p0, curve.p1]
    if isinstance(curve, Arc):
        for k in range(4):
            ang = k * math.pi / 2.0
            if curve.contains_angle(ang):
                pts.append(curve.center + curve.radius * np.array([math.cos(ang), math.sin(ang)]))
    pts = np.array(pts)
    return pts.min(axis=0), pts.max(axis=0)


def loop_signed_area(loop) -> float:
    """Taken about the loop's first point: far from the origin (a part placed at 1e4 of
    its size) the products of absolute coordinates would cancel away the area's digits."""
    origin = np.asarray(loop[0].p0, dtype=float)
    return float(sum(c.signed_area_term(origin) for c in loop))


def winding_number(loop, q) -> int:
    """How many times the closed loop winds around point q (q must not lie on it)."""
    return int(winding_numbers(loop, q)[0])


def winding_numbers(loop, points: np.ndarray) -> np.ndarray:
    """How many times the closed loop winds around each point (none may lie on it): the
    angle each curve's end points subtend, plus a whole turn for a point inside the
    circular segment an arc bounds with its chord."""
    q = np.asarray(points, dtype=float).reshape(-1, 2)
    total = np.zeros(len(q))
    for c in loop:
        a, b = c.p0 - q, c.p1 - q
        cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
        total += np.arctan2(cross, (a * b).sum(axis=1))
        if isinstance(c, Arc):
            inside = np.hypot(*(q - c.center).T) < c.radius
            if not c.is_full:
                # Which side of the chord q lies on: the very number whose sign chose the
                # chord's angle above (+pi or -pi for q near the chord), so that round-off
                # cannot pick one side there and the other here (a moved copy of a part
                # had a hole "outside" its outer loop).
                inside &= cross * cross2(c.p1 - c.p0, c.midpoint() - c.p0) > 0.0
            total += np.where(inside, TWO_PI if c.sweep > 0 else -TWO_PI, 0.0)
    return np.rint(total / TWO_PI).astype(int)


def diameter_of(points) -> float:
    """The largest distance between two of the points: a size that a turned, moved or
    mirrored copy shares (a bounding box's is not)."""
    pts = np.unique(np.asarray(points, dtype=float).reshape(-1, 2), axis=0)
    if len(pts) > 3:
        from scipy.spatial import ConvexHull, QhullError

        try:
            pts = pts[ConvexHull(pts).vertices]
        except QhullError:
            pass  # all on one line: every point is a candidate
    return float(np.sqrt(((pts[:, None, :] - pts[None, :, :]) ** 2).sum(-1).max()))


def distances_to_segment(points, a, b) -> np.ndarray:
    """Distances of points from the segment a-b (from a where a and b coincide)."""
    points = np.asarray(points, dtype=float)
    d = b - a
    length2 = float(d @ d)
    t = np.zeros(len(points)) if length2 == 0.0 else np.clip((points - a) @ d / length2, 0, 1)
    return np.hypot(*(points - (a + t[:, None] * d)).T)
