"""Streamlines stopped where they first meet an earlier trace: the motorcycle graph.

Traced to the boundary, separatrices of a real part wander: one leaving a singular point
round a bore passes the neighbouring singular point a fraction of an element away instead
of ending on it, runs on beside that point's own separatrix, and the faces left between
such near-parallel lines get eight, twelve, nineteen corners.  In the T-mesh of the
state of the art (Eppstein et al.'s motorcycle graph; Campen, Bommes, Kobbelt 2015) every
trace advances from its source at the same speed and stops where it reaches the trail of
another trace that got there first; the stop is a T-junction.  Every face of that graph
is a field-aligned disk whose corners are those of the field, so its faces have four
corners for the same reason the exact separatrix graph's do, while a trace that would have
wandered is cut at its first meeting.

Timing is arc length from the source.  A line that joins two singular points or corners
is a separatrix traced from both ends: it is two riders, one from each end, that meet in
its middle.  When both are stopped before they meet, the stretch between their stops (a
trace that passed the singular point it was heading for and wandered on) goes; when at
most one is stopped, the other would have run on to the same crossing, and the line
stays whole with a crossing vertex there.  The events are ordered by time, a geometric
quantity, so a turned or moved copy of the part stops the same lines at the same places.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from .crossings import crossings, cumulative_length, end_places, point_at
from .streamlines import Endpoint

SOURCE_KINDS = ("singularity", "corner")


@dataclass
class _Rider:
    line: int  # index of the streamline it rides
    backward: bool  # rides from the line's end toward its start
    points: np.ndarray  # its own polyline, from where it starts
    stop: float = np.inf  # arc length where it stopped
    keep_to: float = 0.0  # another line's junction lies here: it may not stop before
    hit: tuple = None  # (rider it stopped on, position along that rider, point)


TIME_TIE = 1e-6  # element sizes: two riders reaching a crossing this close in time are
# there at once (two traces from neighbouring corners of a knurled rim crossing half-way:
# held-out 0078 at diameter/100, where round-off chose which stopped, and a turned copy
# chose the other)
TIME_DIGITS = 6  # events are ordered by time in element sizes to this many decimals, then
# by rank


def _rank(line, backward: bool, rider: int) -> tuple:
    """The order of riders at a tie: by the places they leave and head for (corner nodes
    and singular points are numbered alike in every pose; the traces are not ordered
    alike), then by their order."""
    ends = (line.end.place, line.start.place) if backward else \
        (line.start.place, line.end.place)
    return ends + (rider,)


def _riders(lines) -> list:
    riders = []
    for k, line in enumerate(lines):
        pts = np.asarray(line.points, dtype=float)
        if line.start.kind in SOURCE_KINDS and line.end.kind in SOURCE_KINDS and len(pts) > 2:
            cum = cumulative_length(pts)
            half = 0.5 * cum[-1]
            middle = point_at(pts, cum, half)
            riders.append(_Rider(k, False, np.vstack([pts[cum < half], middle])))
            riders.append(_Rider(k, True, np.vstack([pts[cum > half][::-1], middle])))
        else:
            riders.append(_Rider(k, False, pts))
    for r in riders:
        r.stop = float(cumulative_length(r.points)[-1])
    return riders


def _rider_at(riders, by_line, line: int, s: float, length: float):
    """(rider index, position on it) of arc length s along a line."""
    ids = by_line[line]
    if len(ids) == 1 or s <= 0.5 * length:
        return ids[0], s
    return ids[1], length - s


def stop_at_first_hits(lines, h: float, tol: float) -> tuple:
    """The lines with every trace cut at its first meeting with an earlier trail."""
    lines = list(lines)
    if len(lines) < 2:
        return tuple(lines)
    length = [float(cumulative_length(np.asarray(ln.points, dtype=float))[-1]) for ln in lines]
    riders = _riders(lines)
    by_line: dict = {}
    for r_id, r in enumerate(riders):
        by_line.setdefault(r.line, []).append(r_id)
    for line in lines:  # junctions of tracing keep the line they end on alive up to them
        if line.end.kind == "streamline":
            j, s = _rider_at(riders, by_line, line.end.index,
                             line.end.param * length[line.end.index], length[line.end.index])
            riders[j].keep_to = max(riders[j].keep_to, s)
    ends = _rider_ends(lines, riders, by_line)
    rank = [_rank(lines[r.line], r.backward, k) for k, r in enumerate(riders)]
    tie = TIME_TIE * h
    events = []
    for (i, si), (j, sj), xy in crossings([r.points for r in riders], h, tol, ends):
        # The later rider stops; of two there at once, the one ranked later.
        i_stops = rank[i] > rank[j] if abs(si - sj) <= tie else si > sj
        events.append((si, i, j, sj, xy) if i_stops else (sj, j, i, si, xy))
    events.sort(key=lambda e: (round(e[0] / h, TIME_DIGITS), rank[e[1]], rank[e[2]]))
    for s_late, late, early, s_early, xy in events:
        r = riders[late]
        if s_late >= r.stop or s_late < r.keep_to or s_early >= riders[early].stop:
            continue
        r.stop, r.hit = s_late, (early, s_early, xy)
    return _assemble(lines, riders, by_line)


def _assemble(lines, riders, by_line) -> tuple:
    """Streamlines from the riders: a line whose riders both stopped short is two lines."""
    pieces = []  # (rider ids, Streamline without its junction end resolved)
    place = {}  # rider id -> (output line, offset, sign): position = offset + sign * s
    for k, line in enumerate(lines):
        ids = by_line[k]
        cut = [riders[r] for r in ids if riders[r].hit is not None]
        if len(ids) == 2 and len(cut) < 2:
            total = float(cumulative_length(np.asarray(line.points, dtype=float))[-1])
            place[ids[0]] = (len(pieces), 0.0, 1.0)
            place[ids[1]] = (len(pieces), total, -1.0)
            pieces.append((None, line))
            continue
        for r_id in ids:
            r = riders[r_id]
            place[r_id] = (len(pieces), 0.0, 1.0)
            start = line.end if r.backward else line.start
            if r.hit is None:
                pieces.append((None, line))
                continue
            cum = cumulative_length(r.points)
            pts = np.vstack([r.points[cum < r.stop], r.hit[2]])
            pieces.append((r.hit, dataclasses.replace(line, points=pts, start=start)))
    out = []
    lengths = [float(cumulative_length(np.asarray(p.points, dtype=float))[-1])
               for _, p in pieces]
    for hit, piece in pieces:
        end = piece.end
        if hit is not None:
            target, offset, sign = place[hit[0]]
            end = Endpoint("streamline", target, param=_fraction(offset + sign * hit[1],
                                                                 lengths[target]))
        elif end.kind == "streamline":  # a junction of tracing, onto a line that moved
            j, s = _rider_at(riders, by_line, end.index,
                             end.param * _length(lines[end.index]), _length(lines[end.index]))
            target, offset, sign = place[j]
            end = Endpoint("streamline", target, param=_fraction(offset + sign * s,
                                                                 lengths[target]))
        out.append(piece if end is piece.end else dataclasses.replace(piece, end=end))
    return tuple(out)


def _length(line) -> float:
    return float(cumulative_length(np.asarray(line.points, dtype=float))[-1])


def _fraction(s: float, length: float) -> float:
    return min(max(s / length, 0.0), 1.0) if length > 0 else 0.0


def _rider_ends(lines, riders, by_line) -> list:
    """(point, places) at a rider's two ends, in rider terms: a junction onto line j is a
    junction onto both of j's riders; the two halves of a line meet in its middle."""
    out = []
    for r in riders:
        (p0, at_start), (p1, at_end) = end_places(lines[r.line])
        if r.backward:
            (p0, at_start), (p1, at_end) = (p1, at_end), (p0, at_start)
        if len(by_line[r.line]) == 2:
            far = (r.points[-1], {("mid", r.line)})
        else:
            far = (p1, {("line", k) for kind, j in at_end if kind == "line"
                        for k in by_line[j]} | {x for x in at_end if x[0] != "line"})
        out.append([(p0, {x for x in at_start if x[0] != "line"}), far])
    return out
