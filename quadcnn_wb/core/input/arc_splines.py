"""Free curves (B-splines, ellipses) as arc splines: the one rule the CAD importer and
FreeCAD's sketches and faces both follow.

Biarcs, pairs of arcs meeting tangentially, keep the curve's own tangent at every joint,
so no joint is a corner and the frame field turns with the curve; a polyline kinks at
every vertex and gives gmsh a vertex to put a node on at each (a gear's sampled flanks
left no 2048-node background).
"""

from __future__ import annotations

import math

import numpy as np

from .curves import Arc, Line, distances_to_segment

DENSE = 512  # samples a curve is fitted to
# Pieces are at least this long, relative to the part: four times the crumbs healing
# drops (input.healing.HEAL_TOL).  A knurled ring's 840 small B-splines, sampled within
# 1e-4 of their own span, gave 18728 pieces of 5e-5 of the part, all dropped as crumbs,
# and the loop was refused as open.
MIN_PIECE = 4e-4
# They follow the curve within the healing tolerance (what no mesh shows), relative to the
# part: fitted to a tenth of a gear flank's micrometre, the flanks took so many arcs that
# a 2048-node background could not be had.
CURVE_TOLERANCE = 1e-4


def arc_spline(points: np.ndarray, tangents: np.ndarray, part_size: float) -> list:
    """Biarcs (pairs of arcs meeting tangentially, given as point triples) through samples
    of a curve, each touching the curve's tangent at its ends and within CURVE_TOLERANCE
    of the part of the samples it stands for, halving a stretch until it fits.  The
    pieces meet with the curve's own tangent, so no joint of them is a corner.  A stretch
    shorter than 2 MIN_PIECE of the part (or four samples) is taken as it is."""
    tol, shortest = CURVE_TOLERANCE * part_size, MIN_PIECE * part_size
    lengths = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])
    # Where the derivative vanishes (a B-spline's doubled end control point) the
    # samples' own direction stands in; where that vanishes too, no biarc is tried.
    norms = np.hypot(*tangents.T)
    still = norms <= 1e-9 * max(float(norms.max()), 1e-300)
    tangents = np.where(still[:, None], np.gradient(points, axis=0), tangents)
    norms = np.hypot(*tangents.T)
    with np.errstate(divide="ignore", invalid="ignore"):
        units = tangents / norms[:, None]
    out = []
    spans = [(0, len(points) - 1)]
    while spans:
        i, j = spans.pop()
        pieces = _biarc(points[i], units[i], points[j], units[j])
        fits = pieces is not None and _within(points[i:j + 1], pieces, tol)
        if not fits and j - i >= 4 and lengths[j] - lengths[i] >= 2 * shortest:
            k = (i + j) // 2
            spans.extend([(k, j), (i, k)])  # the first half next: pieces come out in order
            continue
        out.extend(pieces if fits else [_arc_or_line(points[i:j + 1])])
    return out


def _biarc(p0, t0, p1, t1):
    """Two arcs (or lines) from p0 leaving along t0 to p1 arriving along t1, meeting
    tangentially halfway along equal tangent legs; None where no such pair exists."""
    v = p1 - p0
    if not (np.all(np.isfinite(t0)) and np.all(np.isfinite(t1))) or float(v @ v) == 0.0:
        return None
    t = t0 + t1
    along = 1.0 - float(t0 @ t1)
    if along < 1e-12:  # parallel tangents
        ahead = float(v @ t1)
        if ahead <= 0.0:
            return None
        leg = float(v @ v) / (4.0 * ahead)
    else:
        vt = float(v @ t)
        leg = (-vt + math.sqrt(vt * vt + 2.0 * along * float(v @ v))) / (2.0 * along)
    if not leg > 0.0:
        return None
    a, b = p0 + leg * t0, p1 - leg * t1
    joint = 0.5 * (a + b)
    first, second = _tangent_arc(p0, t0, joint), _tangent_arc(joint, b - a, p1)
    return None if first is None or second is None else [first, second]


def _tangent_arc(p, t, q):
    """The arc from p leaving along t to q (a point triple), or a line when q lies ahead
    on t; None when q lies behind."""
    w = q - p
    n = np.array([-t[1], t[0]]) / math.hypot(*t)
    height = float(n @ w)
    length2 = float(w @ w)
    if abs(height) <= 1e-9 * length2 ** 0.5:
        return Line(p, q) if float(t @ w) > 0.0 else None
    radius = length2 / (2.0 * height)  # signed: positive turning left
    center = p + radius * n
    a0 = math.atan2(*(p - center)[::-1])
    sweep = (math.atan2(*(q - center)[::-1]) - a0) % (2 * math.pi)
    if radius < 0.0:
        sweep -= 2 * math.pi
    mid = center + abs(radius) * np.array([math.cos(a0 + sweep / 2), math.sin(a0 + sweep / 2)])
    return (p, mid, q)


def _within(points: np.ndarray, pieces: list, tol: float) -> bool:
    """Whether every sample lies within ``tol`` of one of the pieces."""
    off = np.full(len(points), np.inf)
    for piece in pieces:
        if isinstance(piece, Line):
            off = np.minimum(off, distances_to_segment(points, piece.p0, piece.p1))
        else:
            arc = Arc.through(*piece)
            dist = np.abs(np.hypot(*(points - arc.center).T) - arc.radius)
            ends = np.minimum(np.hypot(*(points - piece[0]).T), np.hypot(*(points - piece[2]).T))
            rel = points - arc.center
            turned = (np.arctan2(rel[:, 1], rel[:, 0]) - arc.a0) * np.sign(arc.sweep)
            inside = np.mod(turned, 2 * math.pi) <= abs(arc.sweep)
            off = np.minimum(off, np.where(inside, dist, ends))
    return bool(off.max() <= tol)


def _arc_or_line(points: np.ndarray):
    """The stretch as one arc through its ends and middle, or a line where those three
    are in a line."""
    a, m, b = points[0], points[len(points) // 2], points[-1]
    chord = float(np.hypot(*(b - a)))
    return (a, m, b) if abs(float(np.cross(b - a, m - a))) > 1e-6 * chord**2 else Line(a, b)
