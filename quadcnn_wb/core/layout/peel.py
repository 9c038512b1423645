"""Five- and six-cornered faces cut into quadrilaterals by straight cuts from a corner to
a side, where no centre sees their sides (subdivide.py).

A long curved strip whose end has an extra corner or two (a trace's T on the end, a
notch's step: held-out 0043's ring halves, 0037's strip under a row of notches) has no
point from which spokes reach the middles of all its sides, and no straight cut joins
two opposite corners inside it; it used to stay a free face of unstructured quads.  A
cut from a corner to the nearest point of a side two corners on splits off a
quadrilateral and leaves a face of one corner fewer: a pentagon is two blocks, a
hexagon a block and a pentagon.  The cut's ends are a corner that gets one more edge and
a T on a side (regular, as any trace's end on a side), so no valence-5 centre either;
the corner is regular too where it is wide (WIDE_CORNER), so cuts from wide corners go
first.  Each cut must stay inside the face and leave at least MIN_CUT_ANGLE at both of
its ends; of those, the one whose least angle is widest is taken (a tie goes to the
face's first corner, as the hexagon's opposite-corner cut does).
"""

from __future__ import annotations

import math

import numpy as np

from .crossings import cumulative_length, point_at
from .face_geometry import ccw_angle, segment_inside

MIN_CUT_ANGLE = math.radians(30.0)
# A corner this wide takes two quads as a regular vertex does (DESIGN.md's round(angle /
# 90°)): a cut from it costs no irregular vertex, one from a narrower corner does.
WIDE_CORNER = math.radians(135.0)
FOOT_CLEARANCE = 0.25  # the foot stays this many cut lengths from the side's corners
FOOT_SNAP = 0.1  # ... and takes a vertex already on the side this many cut lengths away
FOOT_STEP = 0.25  # of the nearest foot's distance: how far apart the other feet tried lie
FOOT_STEPS = (0, -1, 1, -2, 2, -3, 3, -4, 4)
INSIDE_SHORT = 1e-6  # share of a cut left out at its foot when testing it is inside
HEADING_SHARE = 0.25  # a side's heading at a corner: this share of its length on ...
HEADING_CUT = 0.5  # ... but no farther than this share of the cut's length


def peel_plan(corner_xy, side_points) -> list | None:
    """[(corner, side, arc length along that side, snap)] for each cut, the later ones in
    the face left by the earlier (see pieces()); None where some step has no cut.
    ``snap``: how near the foot a vertex already on the side is taken instead."""
    corners = [np.asarray(p, dtype=float) for p in corner_xy]
    sides = [np.asarray(s, dtype=float) for s in side_points]
    if len(corners) not in (5, 6):
        return None
    plan = []
    while len(corners) > 4:
        k = len(corners)
        outline = np.vstack([s[:-1] for s in sides])
        best = None
        for c in range(k):
            for j in sorted({(c + 2) % k, (c - 3) % k}):
                found = _cut_to_side(corners, sides, outline, c, j)
                if found is not None and (best is None or _better(found[0], best[0])):
                    best = (found[0], c, j, found[1], found[2])
        if best is None:
            return None
        _, c, j, s, foot = best
        plan.append((c, j, s, FOOT_SNAP * float(np.hypot(*(foot - corners[c])))))
        pts = sides[j]
        cum = cumulative_length(pts)
        first = np.vstack([pts[cum < s], foot])
        second = np.vstack([foot, pts[cum > s]])
        cut = np.vstack([corners[c], foot])
        _, _, corners, sides = pieces(corners, sides, c, j, foot, first, second, cut,
                                      cut[::-1])
    return plan


def pieces(corners, sides, c, j, foot, first, second, cut_out, cut_back) -> tuple:
    """(quad corners, quad sides, rest corners, rest sides) of a face cut from corner c
    to ``foot`` on side j (from corner j to j + 1), which ``first`` and ``second`` are
    the two parts of; ``cut_out`` runs from the corner to the foot, ``cut_back`` back.
    Works alike on points and polylines (the plan) and on vertex ids and half-edges."""
    k = len(corners)

    def at(i):
        return i % k

    if j == at(c + 2):  # the quad holds corners c, c + 1, c + 2 and the foot
        quad = ([corners[c], corners[at(c + 1)], corners[at(c + 2)], foot],
                [sides[c], sides[at(c + 1)], first, cut_back])
        rest = ([foot] + [corners[at(c + 3 + i)] for i in range(k - 2)],
                [second] + [sides[at(c + 3 + i)] for i in range(k - 3)] + [cut_out])
    else:  # j == c - 3: the quad holds the foot, corners c - 2, c - 1 and c
        quad = ([foot, corners[at(c - 2)], corners[at(c - 1)], corners[c]],
                [second, sides[at(c - 2)], sides[at(c - 1)], cut_out])
        rest = ([corners[at(c + i)] for i in range(k - 2)] + [foot],
                [sides[at(c + i)] for i in range(k - 3)] + [first, cut_back])
    return quad[0], quad[1], rest[0], rest[1]


def _cut_to_side(corners, sides, outline, c, j):
    """((wide corner, least angle), arc length, foot) of the best cut from corner c to
    side j (see _better), or None where every one leaves the face, ends too near the
    side's corners or makes an angle under MIN_CUT_ANGLE.  The feet tried: the side's
    point nearest the corner, then FOOT_STEP of that distance further either way (a
    strip's end whose corners face each other across it has its nearest point on a
    corner: 0043's ring half, whose cut then slants, halving the corner's angle)."""
    corner = corners[c]
    pts = sides[j]
    cum = cumulative_length(pts)
    nearest, foot = _nearest_on(pts, corner)
    width = float(np.hypot(*(foot - corner)))
    if not width > 0.0:
        return None
    best = None
    for step in FOOT_STEPS:
        s = nearest + step * FOOT_STEP * width
        if not 0.0 < s < float(cum[-1]):
            continue
        found = _cut_at(corners, sides, outline, c, j, s, cum)
        if found is not None and (best is None or _better(found[0], best[0])):
            best = found
    return best


def _cut_at(corners, sides, outline, c, j, s, cum):
    """_cut_to_side's figures for the foot at arc length s of side j."""
    corner = corners[c]
    pts = sides[j]
    k = int(np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(pts) - 2))
    foot = point_at(pts, cum, s)
    tangent = pts[k + 1] - pts[k]
    tangent = tangent / max(float(np.hypot(*tangent)), 1e-300)
    length = float(np.hypot(*(foot - corner)))
    if not length > 0.0 or min(s, float(cum[-1]) - s) < FOOT_CLEARANCE * length:
        return None
    # The foot lies on the outline: tested short of it, so round-off there cannot
    # read as a crossing.
    if not segment_inside(outline, corner, foot - INSIDE_SHORT * (foot - corner)):
        return None
    cut = foot - corner
    leaving = _heading(sides[c], length)
    back = _heading(sides[(c - 1) % len(corners)][::-1], length)
    at_corner = (ccw_angle(leaving, cut), ccw_angle(cut, back))
    across = math.acos(float(np.clip(-cut @ tangent / length, -1.0, 1.0)))
    angles = at_corner + (across, math.pi - across)
    least = min(angles)
    wide = at_corner[0] + at_corner[1] >= WIDE_CORNER
    return ((wide, least), s, foot) if least >= MIN_CUT_ANGLE else None


def _better(first, second) -> bool:
    """A cut from a wide corner first, then the wider least angle (ties, within
    round-off, keep the earlier)."""
    if first[0] != second[0]:
        return first[0]
    return first[1] > second[1] + 1e-9


def _heading(points, cut_length) -> np.ndarray:
    cum = cumulative_length(points)
    reach = min(HEADING_SHARE * float(cum[-1]), HEADING_CUT * cut_length)
    return point_at(points, cum, reach) - points[0]


def _nearest_on(points, p) -> tuple:
    """(arc length, point) of a polyline's point nearest to p."""
    a, b = points[:-1], points[1:]
    d = b - a
    lengths = np.hypot(*d.T)
    f = np.clip(np.einsum("ij,ij->i", p - a, d) / np.maximum(lengths ** 2, 1e-300), 0.0, 1.0)
    near = a + f[:, None] * d
    gap = np.hypot(*(near - p).T)
    i = int(np.argmin(gap))
    s = float(np.concatenate([[0.0], np.cumsum(lengths)])[i] + f[i] * lengths[i])
    return s, near[i]
