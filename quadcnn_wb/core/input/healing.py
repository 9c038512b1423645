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

from .curves import TWO_PI, Arc, Line, cross2, distances_to_segment

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
    """Runs of arcs of one circle and runs of collinear lines as one curve each; a loop of
    arcs of one circle that closes becomes that circle.

    Every joint is judged on the curves as given and a run is merged whole or not at all,
    so the result does not hang on where the loop starts or which way it runs (a mirrored
    copy heals alike), and healing a healed loop changes nothing.  A run of lines merges
    only when all its inner vertices lie within ``tol`` of the line that replaces it:
    judged joint by joint, a finely sampled curve (a knurled hole stored as short lines)
    passes everywhere and would collapse onto its chord."""
    curves = list(loop)
    n = len(curves)
    if n == 1 and isinstance(curves[0], Arc) and not curves[0].is_full:
        return [_close_circle(curves[0])]
    if n < 2:
        return curves
    joins = [_continues(curves[k], curves[(k + 1) % n], tol) for k in range(n)]
    if all(joins):
        whole = _whole_circle(curves, tol)
        if whole is None:
            return curves  # no break between runs: not a circle, so left to validation
        notes.append(f"loop {li}: {n - 1} joint(s) between arcs of one circle merged")
        return [whole]
    first = (joins.index(False) + 1) % n  # runs start after a joint that stays
    runs, run = [], []
    for k in range(n):
        i = (first + k) % n
        run.append(i)
        if not joins[i]:
            runs.append(run)
            run = []
    pieces, merged = [], {"arc": 0, "line": 0}
    for run in runs:
        given = [curves[i] for i in run]
        pieces.append(_merge_run(given, tol) if len(given) > 1 else given)
        merged[given[0].kind] += len(given) - len(pieces[-1])
    first_run = next(k for k, run in enumerate(runs) if 0 in run)  # keep the loop's start
    out = [c for piece in pieces[first_run:] + pieces[:first_run] for c in piece]
    if merged["arc"]:
        notes.append(f"loop {li}: {merged['arc']} joint(s) between arcs of one circle merged")
    if merged["line"]:
        notes.append(f"loop {li}: {merged['line']} joint(s) of collinear lines merged")
    return out


def _continues(a, b, tol: float) -> bool:
    """Whether b carries on a's curve: both lines, same way, their joint within ``tol``
    of the line from a's start to b's end; or arcs of one circle turning the same way."""
    if isinstance(a, Line) and isinstance(b, Line):
        if float(np.dot(a.p1 - a.p0, b.p1 - b.p0)) <= 0.0:
            return False
        return _off_line(a.p1, a.p0, b.p1) <= tol
    if isinstance(a, Arc) and isinstance(b, Arc):
        if a.is_full or b.is_full or (a.sweep > 0) != (b.sweep > 0):
            return False
        return bool(np.hypot(*(a.center - b.center)) <= tol and abs(a.radius - b.radius) <= tol)
    return False


def _off_line(p, a, b) -> float:
    """Distance of p from the line through a and b."""
    d = b - a
    return abs(cross2(p - a, d)) / float(np.hypot(*d))


def _merge_run(run, tol: float) -> list:
    """The curves that replace a run of curves each continuing the one before: arcs of one
    circle become one arc (unless they wrap round: an overlap for the validation to
    report); lines keep only the vertices needed to stay within ``tol`` of every given
    vertex (Douglas-Peucker), so a finely sampled curve keeps its shape."""
    if isinstance(run[0], Line):
        points = [run[0].p0] + [c.p1 for c in run]
        kept = _kept_vertices(points, tol)
        return [Line(points[i], points[j]) for i, j in zip(kept, kept[1:])]
    center = np.mean([c.center for c in run], axis=0)
    radius = float(np.mean([c.radius for c in run]))
    sweep = float(sum(c.sweep for c in run))
    if abs(sweep) >= TWO_PI - tol / radius:
        return list(run)
    a0 = math.atan2(run[0].p0[1] - center[1], run[0].p0[0] - center[0])
    return [Arc(center, radius, a0, sweep, run[0].p0, run[-1].p1)]


TIE = 1e-9  # vertices this close (relative) to the farthest one are kept with it


def _kept_vertices(points, tol: float) -> list:
    """Indices of the polyline vertices that keep it within ``tol`` of all of them: the
    ends, then recursively the farthest vertex from each chord while it is beyond
    ``tol``.  Vertices tied for farthest are all kept, so a symmetric run keeps a
    symmetric set whichever way it is walked."""
    pts = np.asarray(points, dtype=float)
    kept = {0, len(pts) - 1}
    spans = [(0, len(pts) - 1)]
    while spans:
        i, j = spans.pop()
        if j - i < 2:
            continue
        d = distances_to_segment(pts[i + 1:j], pts[i], pts[j])
        far = float(d.max())
        if far <= tol:
            continue
        cuts = [i] + [i + 1 + k for k in np.flatnonzero(d >= far * (1.0 - TIE))] + [j]
        kept.update(cuts)
        spans.extend(zip(cuts, cuts[1:]))
    return sorted(kept)


def _whole_circle(curves, tol: float):
    """The circle a loop of arcs of one circle closes into, or None."""
    if not isinstance(curves[0], Arc):
        return None
    radius = float(np.mean([c.radius for c in curves]))
    sweep = float(sum(c.sweep for c in curves))
    if abs(sweep) > TWO_PI + tol / radius:
        return None  # wraps round more than once: an overlap
    # (short of a full turn only by crumbs dropped before: the loop was checked closed)
    center = np.mean([c.center for c in curves], axis=0)
    return _full_circle(center, radius, curves[0].p0, sweep > 0)


def _close_circle(arc: Arc) -> Arc:
    """A single arc whose ends met within tolerance is the whole circle."""
    return _full_circle(arc.center, arc.radius, arc.p0, arc.sweep > 0)


def _full_circle(center, radius: float, start, counter_clockwise: bool) -> Arc:
    a0 = math.atan2(start[1] - center[1], start[0] - center[0])
    p = np.asarray(center) + radius * np.array([math.cos(a0), math.sin(a0)])
    return Arc(np.asarray(center, dtype=float), float(radius), a0,
               TWO_PI if counter_clockwise else -TWO_PI, p, p.copy())


ON_CIRCLE = 1e-8  # relative to the part's size: an arc end this near its circle is on it
# (a part a thousandth of its coordinates' size, 1e4 off the origin, holds its points to
# about 2e-9 of its size: such arcs stay as given, their corners' angles read alike)


def arcs_through_their_ends(loop, size: float) -> list:
    """Each arc whose ends are off its circle by more than ON_CIRCLE (healing moved them:
    a joined gap, a merged run's averaged circle; or a CAD kernel's vertex lies within
    its tolerance of the curve) is replaced by the arc through its ends and its old
    middle.

    An arc is stored by its circle and its ends; one whose ends are off its circle has
    a kink at each, and its JSON (ends and middle, DESIGN.md) reads back as another
    circle: on a part's near-full rim a 5e-6 gap moved the centre by 2e-4, and a part
    saved as JSON and loaded again was meshed differently (held-out 0043)."""
    out = []
    for c in loop:
        if isinstance(c, Arc) and not c.is_full:
            off = max(abs(float(np.hypot(*(p - c.center))) - c.radius) for p in (c.p0, c.p1))
            if off > ON_CIRCLE * size:
                c = Arc.through(c.p0, c.midpoint(), c.p1)
        out.append(c)
    return out


# A curve end the CAD file joins to its neighbour's (one shared vertex) is moved onto
# that vertex from up to this far, relative to the part's size: a kernel's vertex
# tolerance covers such gaps (the fan hub's hexagonal bore in pythonocc's Ventilator.stp:
# its edges end 0.014 mm, 7e-4 of the hub, off the vertices they share, and OCCT, gmsh
# and FreeCAD take the wire as closed).  Below the finest element the mesher is asked
# for (about 1e-3 of the part); ends with no shared vertex keep HEAL_TOL.
VERTEX_SNAP = 1e-3


def onto_shared_vertices(pieces: list, start, end, floor: float,
                         limit: float) -> tuple[list, list]:
    """(``pieces`` of one CAD edge with their first start moved onto the vertex ``start``
    and their last end onto ``end``, the moves made).  An end moves only where its vertex
    is given (shared with the next edge) and more than ``floor`` (what the joining of
    gaps heals anyway: those parts stay exactly as they were) but at most ``limit`` away;
    otherwise it stays, for validation to judge the gap.  Pieces are lines, arcs or point
    triples."""
    if not pieces or _is_loop(pieces[0]):
        return pieces, []
    out, moves = list(pieces), []
    if start is not None:
        gap = float(np.hypot(*(np.asarray(start) - piece_ends(out[0])[0])))
        if floor < gap <= limit:
            out[0] = _with_start(out[0], np.asarray(start, dtype=float))
            moves.append(gap)
    if end is not None:
        gap = float(np.hypot(*(np.asarray(end) - piece_ends(out[-1])[1])))
        if floor < gap <= limit:
            turned = _with_start(reversed_piece(out[-1]), np.asarray(end, dtype=float))
            out[-1] = reversed_piece(turned)
            moves.append(gap)
    return out, moves


def vertex_note(li: int, moved: list) -> str:
    """What healing says about the curve ends moved onto their shared vertices."""
    return (f"loop {li}: moved {len(moved)} curve end(s) onto the vertex they share with "
            f"the next curve in the CAD file (up to {max(moved):.3g} off it)")


def piece_ends(piece):
    """(start, end) of a line, an arc or a (start, middle, end) point triple."""
    if isinstance(piece, tuple):
        return np.asarray(piece[0], dtype=float), np.asarray(piece[-1], dtype=float)
    return piece.p0, piece.p1


def _is_loop(piece) -> bool:
    return isinstance(piece, Arc) and piece.is_full


def _with_start(piece, p0):
    if isinstance(piece, tuple):
        return (p0,) + tuple(piece[1:])
    return piece.with_start(p0)


def reversed_piece(piece):
    """The piece run the other way (a point triple, reversed)."""
    return tuple(piece[::-1]) if isinstance(piece, tuple) else piece.reversed()
