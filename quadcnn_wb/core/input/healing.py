"""Heal what CAD kernels deliver before the domain is validated.

CAD kernels store a hole as two to four arcs, a fillet run as several arcs of one circle,
a straight edge split at a seam, and leave gaps between edge ends up to their vertex
tolerances (micrometres on a 300 mm part, a few 1e-5 of its size).  Refusing those as
open or self-overlapping loops refuses most real parts, so within HEAL_TOL of the part's
size ends are joined, crumbs shorter than that are dropped, consecutive arcs of one
circle and consecutive collinear lines become one curve.  HEAL_TOL is ten times below
the finest element the mesher is ever asked for (about 1e-3 of the part), so nothing a
mesh could show is changed.  Each change is reported in
words, so a user can see that the part was touched.  Anything larger stays an error for
the validation that follows: real gaps and real crossings are not guessed away.
"""

from __future__ import annotations

import math

import numpy as np

from .curves import TWO_PI, Arc, Line, cross2

HEAL_TOL = 1e-4  # relative to the part's size (bounding-box diagonal)


def drop_crumbs(loops, tol: float, notes: list) -> list:
    """Segments shorter than ``tol`` (lines, and arcs given as point triples) are dropped;
    their neighbours' ends are joined afterwards like any small gap."""
    out = []
    for li, loop in enumerate(loops):
        kept = [c for c in loop if _extent(c) > tol]
        if len(kept) < len(loop) and kept:
            notes.append(f"loop {li}: dropped {len(loop) - len(kept)} segment(s) shorter "
                         f"than {tol:.3g}")
            out.append(kept)
        else:
            out.append(list(loop))
    return out


def _extent(curve) -> float:
    if isinstance(curve, tuple):
        pts = np.array(curve)
        return float(np.hypot(*np.ptp(pts, axis=0)))
    if isinstance(curve, Arc) and curve.is_full:
        return 2.0 * curve.radius
    return float(np.hypot(*(curve.p1 - curve.p0))) if isinstance(curve, Line) else curve.length


def report_gaps(loops, eps: float, notes: list) -> None:
    """Say which loops had end gaps between ``eps`` (exact) and the healing tolerance;
    the caller has refused larger ones and joins these."""
    for li, loop in enumerate(loops):
        if len(loop) < 2:
            continue
        gaps = [float(np.hypot(*(loop[(k + 1) % len(loop)].p0 - c.p1)))
                for k, c in enumerate(loop)]
        healed = [g for g in gaps if g > eps]
        if healed:
            notes.append(f"loop {li}: joined {len(healed)} gap(s) between segment ends "
                         f"(largest {max(healed):.3g})")


def merge_curves(loop, li: int, tol: float, notes: list) -> list:
    """Consecutive arcs of one circle and consecutive collinear lines as one curve; a
    loop of arcs of one circle that closes becomes that circle."""
    curves = list(loop)
    merged_arcs = merged_lines = 0
    changed = True
    while changed and len(curves) > 1:
        changed = False
        for k in range(len(curves)):
            a, b = curves[k], curves[(k + 1) % len(curves)]
            joined = _join(a, b, tol)
            if joined is None:
                continue
            if isinstance(a, Arc):
                merged_arcs += 1
            else:
                merged_lines += 1
            if k + 1 < len(curves):
                curves[k:k + 2] = [joined]
            else:  # the last and the first: the loop now starts where the last one did
                curves = [joined] + curves[1:-1]
            changed = True
            break
    if len(curves) == 1 and isinstance(curves[0], Arc) and not curves[0].is_full:
        curves = [_close_circle(curves[0])]
    if merged_arcs:
        notes.append(f"loop {li}: {merged_arcs} joint(s) between arcs of one circle merged")
    if merged_lines:
        notes.append(f"loop {li}: {merged_lines} joint(s) of collinear lines merged")
    return curves


def _join(a, b, tol: float):
    """One curve for a followed by b, or None when they are not parts of one curve."""
    if isinstance(a, Line) and isinstance(b, Line):
        da, db = a.p1 - a.p0, b.p1 - b.p0
        if float(np.dot(da, db)) <= 0.0:
            return None
        whole = Line(a.p0, b.p1)
        if abs(cross2(b.p1 - a.p0, a.p1 - a.p0)) / whole.length > tol:
            return None
        return whole
    if isinstance(a, Arc) and isinstance(b, Arc):
        if a.is_full or b.is_full or (a.sweep > 0) != (b.sweep > 0):
            return None
        if np.hypot(*(a.center - b.center)) > tol or abs(a.radius - b.radius) > tol:
            return None
        sweep = a.sweep + b.sweep
        if abs(sweep) > TWO_PI + tol / a.radius:
            return None  # wraps over itself: an overlap for the validation to report
        center = 0.5 * (a.center + b.center)
        radius = 0.5 * (a.radius + b.radius)
        a0 = math.atan2(a.p0[1] - center[1], a.p0[0] - center[0])
        if abs(abs(sweep) - TWO_PI) <= tol / radius:
            return _full_circle(center, radius, a.p0, sweep > 0)
        return Arc(center, radius, a0, sweep, a.p0, b.p1)
    return None


def _close_circle(arc: Arc) -> Arc:
    """A single arc whose ends met within tolerance is the whole circle."""
    return _full_circle(arc.center, arc.radius, arc.p0, arc.sweep > 0)


def _full_circle(center, radius: float, start, counter_clockwise: bool) -> Arc:
    a0 = math.atan2(start[1] - center[1], start[0] - center[0])
    p = np.asarray(center) + radius * np.array([math.cos(a0), math.sin(a0)])
    return Arc(np.asarray(center, dtype=float), float(radius), a0,
               TWO_PI if counter_clockwise else -TWO_PI, p, p.copy())
