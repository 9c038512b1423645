"""No sliver wedge at a corner: a line that reaches a corner hard beside one of its sides
ends on the corner's next line instead.

A separatrix leaving a singular point beside a concave fillet can run up the side of a
slot and into the slot's corner a fraction of an element from the side all the way (a
crank web at diameter/100: a valence-5 point at the root fillet, its line into the
300° corner at the top, 22° from the side there).  Ended on the corner, it splits the
corner's interior into its own sectors plus a 22° wedge against the side, and the face
between the line and the side has three corners (the wedge's tip is no corner): its
quads were unstructured.  The corner's own lines already give it the quads its angle
asks for, so the arriving line is a T-junction a short way along the corner's line on
the wedge's far side, and the face is a strip with four corners that quantization can
keep one element wide or collapse.

What is a wedge is measured from the corner along the lines and the boundary curves, so
a turned, moved or mirrored copy moves the same lines.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .crossings import cumulative_length, point_at
from .field_rules import bent_to, corner_endpoint
from .streamlines import Endpoint
from .tracing import SNAP_BLEND

WEDGE_ANGLE = math.radians(45)  # a sector this narrow beside a line is a wedge, where the
# corner has more sectors than its angle asks quads
HEADING_REACH = 0.5  # element sizes from the corner to where a line's heading is read
JUNCTION_REACH = 0.5  # element sizes along the corner's line to the new T-junction ...
JUNCTION_SHARE = 0.4  # ... but at most this share of that line
ANGLE_TIE = 1e-9  # radians: sectors this close in angle are equal (no pose decides)


def without_corner_wedges(domain, background, lines, size: float) -> tuple:
    """``lines`` with every line that ends in a corner within WEDGE_ANGLE of one of the
    corner's sides moved to end on the corner's next line (the nearest one turning away
    from that side), where that line is long enough and no other line ends on the stretch
    the junction passes."""
    lines = list(lines)
    h = background.element_size
    moves = []
    for node in sorted(int(n) for n in background.corner_nodes):
        moves.extend(_wedge_moves(domain, background, lines, node, size, h))
    for k, target, s in moves:
        lines = _end_on(lines, k, target, s, h)
    return tuple(lines)


def _rays(lines, node: int) -> list:
    """(line, 0 for its start or 1 for its end) of every line with an end at the corner:
    ended there, or ended on another line's end that is the corner."""
    out = []
    for k, line in enumerate(lines):
        for which, end in enumerate((line.start, line.end)):
            if end.kind == "corner" and end.index == node:
                out.append((k, which))
            elif which == 1 and end.kind == "streamline" and end.param in (0.0, 1.0):
                other = lines[end.index]
                there = other.start if end.param == 0.0 else other.end
                if there.kind == "corner" and there.index == node:
                    out.append((k, which))
    return out


def _heading(line, which: int, reach: float) -> np.ndarray:
    """Unit direction from the corner end of the line to its point ``reach`` along it."""
    pts = np.asarray(line.points, dtype=float)
    pts = pts[::-1] if which else pts
    cum = cumulative_length(pts)
    p = point_at(pts, cum, min(reach, 0.5 * float(cum[-1])))
    d = p - pts[0]
    return d / max(float(np.hypot(*d)), 1e-300)


def _wedge_moves(domain, background, lines, node, size, h) -> list:
    """(line, corner line it moves onto, arc length along that line from the corner)."""
    corner = corner_endpoint(background, node)
    if node in background.feature_corners or corner.param not in (0.0, 1.0):
        return []  # a feature read as a corner at the mesh's scale: its sides are no curves'
    loop = domain.loops[corner.loop]
    si, t = corner.segment, corner.param
    before = loop[(si - 1) % len(loop)] if t <= 0.0 else loop[si]
    after = loop[si] if t <= 0.0 else loop[(si + 1) % len(loop)]
    leaving = np.asarray(after.tangent(0.0), dtype=float)
    arriving = -np.asarray(before.tangent(1.0), dtype=float)
    rays = _rays(lines, node)
    if not rays:
        return []

    def angle_from_leaving(d) -> float:
        """Counterclockwise from the side leaving the corner: the interior lies there (a
        line along that side is at 0, whichever side of it round-off puts it)."""
        a = math.atan2(leaving[0] * d[1] - leaving[1] * d[0], float(np.dot(leaving, d)))
        a = a if a >= 0.0 else a + 2.0 * math.pi
        return 0.0 if a >= 2.0 * math.pi - ANGLE_TIE else a

    interior = angle_from_leaving(arriving)
    placed = sorted((angle_from_leaving(_heading(lines[k], which, HEADING_REACH * h)), k,
                     which) for k, which in rays)
    placed = [p for p in placed if ANGLE_TIE < p[0] < interior - ANGLE_TIE]
    quads = max(1, round(interior / (0.5 * math.pi)))  # the quads the corner's angle asks for
    if len(placed) + 1 <= quads:
        return []
    bounds = [0.0] + [p[0] for p in placed] + [interior]
    wedges = []  # (sector beside an arriving line, rank, side of that sector)
    for rank, (theta, _k, which) in enumerate(placed):
        if which == 1:
            low, high = theta - bounds[rank], bounds[rank + 2] - theta
            if low <= high + ANGLE_TIE:
                wedges.append((low, rank, -1))
            if high <= low + ANGLE_TIE:
                wedges.append((high, rank, 1))
    if not wedges or min(wedges)[0] >= WEDGE_ANGLE:
        return []
    # The narrowest sector, wherever it is found: the sector between two arriving lines is
    # found once for each, and which of them comes first in the turn from the corner's
    # leaving side is the mirror image's last.  Of the lines that can move, the one with
    # the longer stretch of its own to the corner line moves; a tie moves none.
    narrowest = min(wedges)[0]
    moves = [move for angle, rank, side in wedges if angle <= narrowest + ANGLE_TIE
             for move in _move(lines, placed, rank, side, size)]
    if not moves:
        return []
    keys = [_move_key(lines, move, h) for move in moves]
    if keys.count(max(keys)) > 1 and len(set(moves)) > 1:
        return []
    return [moves[keys.index(max(keys))]]


def _move(lines, placed, rank, side, size) -> list:
    """The move of the arriving line placed at ``rank`` onto the ray across its wider
    sector, on the far side from the wedge (none where there is no such corner line, or
    a junction is already near its corner end)."""
    far = rank - side
    if not 0 <= far < len(placed):
        return []
    _, k, _ = placed[rank]
    _, target, target_which = placed[far]
    if lines[target].end.kind == "streamline" and target_which == 1:
        return []  # itself a junction at the corner: no line of the corner's own
    length = lines[target].length
    s = min(JUNCTION_REACH * size, JUNCTION_SHARE * length)
    if s <= 0.0 or _junction_within(lines, target, target_which, s, length):
        return []
    return [(k, target, s if target_which == 0 else length - s)]


def _move_key(lines, move, h) -> tuple:
    """What decides between two lines that could move at one corner: the longer line,
    then the longer target (rounded: a turned copy must decide alike)."""
    k, target, _ = move
    return round(lines[k].length / h, 6), round(lines[target].length / h, 6)


def _junction_within(lines, target, which, s, length) -> bool:
    """Another line ends on ``target`` within ``s`` of its corner end."""
    for line in lines:
        if line.end.kind == "streamline" and line.end.index == target:
            along = line.end.param * length
            if 0.0 < (along if which == 0 else length - along) <= s:
                return True
    return False


def _end_on(lines, k, target, s, h) -> list:
    """Lines with line k's end moved onto ``target`` at arc length ``s`` from its start,
    the stretch before the end bent there smoothly (tracing's snap blend)."""
    pts = np.asarray(lines[target].points, dtype=float)
    cum = cumulative_length(pts)
    place = point_at(pts, cum, s)
    line = lines[k]
    out = list(lines)
    out[k] = dataclasses.replace(line, points=bent_to(line.points, place, SNAP_BLEND * h),
                                 end=Endpoint("streamline", target,
                                              param=float(s / float(cum[-1]))))
    return out
