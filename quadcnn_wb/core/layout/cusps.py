"""A cusp's tip as one quad: the kite that ends the separatrix running into it.

Where two boundary curves meet at a cusp (tangent arcs, a crank web's horns: an interior
angle below the field's SHARP_LOW), the cross field carries on through the tip as along
a smooth stretch (the short way round, framefield.boundary_values), and the singular
point it puts beside the cusp sends a separatrix into the tip.  Cut along that line, the
tip gets two quads, each with a corner of half the cusp's angle, and the faces either
side cannot be blocks: the field's count wants the tip to hold no quad at all (+2 by
Poincaré-Hopf), two quads give it nothing (0), and the two units missing turned up as
folded block maps (0051 crank web: four faces of unstructured quads at the default size).

Every quad mesh puts at least one quad at a tip, so the layout gives it exactly one and
makes up the other unit where the field's count asks for it: the separatrix stops one
element short of the tip at a point M, from which two short arms run back out to the
two sides, leaning towards the tip (120° between them, 120° from each to the
separatrix).  The kite tip-L-M-R is a block with one quad's corner at the tip, and M is
a valence-3 vertex, the standard split of a three-sided tip.  Nothing here hangs on the
frame of the input: the kite is measured along the separatrix and the boundary.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..field.framefield import SHARP_LOW
from .crossings import crossings, cumulative_length, end_places, point_at
from .field_rules import corner_endpoint, start_triangle
from .streamlines import Endpoint, Streamline
from .tracing import integrate

KITE_REACH = 1.0  # element sizes from the tip to the kite's inner corner M ...
KITE_SHARE = 0.4  # ... but at most this share of the separatrix (less than half: a line
# between two cusps keeps its middle)
ARM_LEAN = math.radians(60)  # between an arm and the direction from M back to the tip
ARM_POINTS = 4  # polyline points per arm
SEARCH = 3.0  # reaches along each side searched for the point nearest M
SEARCH_SAMPLES = 600
MIDLINE_STEP = 0.25  # background sizes between the points of a line from a cusp's tip ...
MIDLINE_WIDTH = 1.5  # ... that follows the horn's middle while it is narrower than this
TANGENT_TIP = math.radians(0.5)  # a cusp this sharp is a horn between tangent curves ...
HORN_WIDTH = 0.5  # ... whose kite sits where the horn is this many sizes wide ...
HORN_SEARCH = 6.0  # ... looked for this many sizes in
HORN_SAMPLES = 60


def with_cusp_kites(domain, background, field, lines, size: float) -> tuple:
    """``lines`` with a kite at every cusp that exactly one of them runs into.  A cusp
    that none runs into (no singular point beside it: a lens between two bores, whose
    two cusps make up the disk's count) gets one, traced from the tip along the field
    until it meets another line or the boundary."""
    cusps = _tips(background, SHARP_LOW)
    tangent = set(_tips(background, TANGENT_TIP))
    lines = list(lines)
    for node in cusps:
        if not _lines_at(lines, node):
            lines.extend(_from_tip(domain, background, field, lines, node))
    cuts = []  # (line, its end at the tip: 0 start, 1 end, reach), from the lines as traced
    for node in cusps:
        at = _lines_at(lines, node)
        if len(at) == 1:
            k, which = at[0]
            total = float(cumulative_length(np.asarray(lines[k].points, dtype=float))[-1])
            reach = KITE_REACH * size
            if node in tangent:  # a horn between tangent curves: as far in as it is wide
                reach = max(reach, _horn_reach(domain, background, node, size))
            cuts.append((k, which, min(reach, KITE_SHARE * total)))
    for k, which, reach in cuts:
        lines = _kite(domain, lines, k, which, reach)
    return tuple(lines)


TIP_MATCH = 1e-6  # element sizes: a mesh node this close to a cusp's tip is its node


def tip_corners(background, nodes, quads, size: float) -> np.ndarray:
    """Per quad corner (N, 4): whether it is a cusp's tip.

    No quad corner at a tip can be better than the tip's angle lets it be: between
    tangent curves that is the angle their chords of one element make, a few degrees, so
    a scaled Jacobian under the pipeline's floor there says nothing about the layout
    (a square with a tangent horn at diameter/100: 0.034 at the tip, and the whole face
    went to gmsh's quads, 0.016 at the same tip).  The quad's other corners say as much
    as anywhere: held-out 0043's quad at a 20-degree tip had its 4th corner on the tip's
    side, flat (0.006), and went out as the mesh's worst."""
    tips = background.nodes[_tips(background, SHARP_LOW)]
    if not len(tips) or not len(nodes):
        return np.zeros(quads.shape, dtype=bool)
    gap = np.hypot(nodes[:, None, 0] - tips[None, :, 0],
                   nodes[:, None, 1] - tips[None, :, 1]).min(axis=1)
    at_tip = gap <= TIP_MATCH * size
    return at_tip[quads]


def _tips(background, below: float) -> list:
    """The corner nodes whose interior angle is under ``below``, in node order."""
    return sorted(int(n) for n, a in zip(background.corner_nodes, background.corner_angles)
                  if a < below)


def _lines_at(lines, node) -> list:
    """(line, 0 for its start or 1 for its end) of the lines that end at a corner node."""
    return [(k, which) for k, line in enumerate(lines)
            for which, end in enumerate((line.start, line.end))
            if end.kind == "corner" and end.index == node]


def _from_tip(domain, background, field, lines, node) -> list:
    """A line from the cusp at ``node`` along the horn's middle and then the field (along
    its bisector where the horn is wide from the tip on), stopped where it first crosses
    one of ``lines`` (a T-junction there), as the motorcycle graph stops traces."""
    corner = corner_endpoint(background, node)
    si, t = corner.segment, corner.param
    loop = domain.loops[corner.loop]
    before = loop[(si - 1) % len(loop)] if t <= 0.0 else loop[si]
    after = loop[si] if t <= 0.0 else loop[(si + 1) % len(loop)]
    bisector = after.tangent(0.0) - before.tangent(1.0)
    if not np.hypot(*bisector) > 0:
        return []
    bisector = bisector / np.hypot(*bisector)
    tip = background.nodes[node]
    h = background.element_size
    tris = np.nonzero((background.triangles == node).any(axis=1))[0]
    start = start_triangle(background.walker, tris, tip, bisector, h)
    # Between tangent curves the bisector runs along both sides, on the boundary, and the
    # field in a horn narrower than an element says little (a trace from the middle of
    # 0042's horn drifted onto one side and ran along it to a corner, and the two faces
    # it left were a two-cornered sliver and a kite's neighbour of three corners).  So
    # the line follows the horn's middle (halfway between the sides' points at equal arc
    # lengths from the tip, which lies inside whatever the sign of round-off) until the
    # sides are MIDLINE_WIDTH sizes apart, and the field from there.
    line = _along_middle(domain, background, field, corner, start)
    if line is None:
        (line,) = integrate(domain, background, field, [(tip, bisector, start, corner)])
    every = list(lines) + [line]
    new = len(lines)
    hits = [((s_i, j, s_j) if i == new else (s_j, i, s_i))
            for (i, s_i), (j, s_j), _ in crossings(
                [np.asarray(x.points, dtype=float) for x in every], h, 1e-9 * domain.size,
                [end_places(x) for x in every])
            if new in (i, j)]
    if hits:
        s, j, s_j = min(hits)
        pts = np.asarray(line.points, dtype=float)
        cum = cumulative_length(pts)
        other = cumulative_length(np.asarray(lines[j].points, dtype=float))[-1]
        line = dataclasses.replace(
            line, points=np.vstack([pts[cum < s], point_at(pts, cum, s)]),
            end=Endpoint("streamline", j, param=float(s_j / other)))
    return [line]


def _along_middle(domain, background, field, corner, start):
    """The line from the cusp at ``corner`` along the horn's middle, then the field
    (see _from_tip); None where the horn is wide from the tip on, or its middle leaves
    the background (``start``: the tip's triangle the line goes into)."""
    tip = background.nodes[corner.index]
    middle = _midline(domain.loops[corner.loop], (corner.segment, corner.param),
                      background.element_size)
    if not len(middle):
        return None
    walk = start
    for point in middle:  # point by point: a curved horn's chord may leave the domain
        found, _, _ = background.walker.locate(np.array([walk]), point[None])
        if found[0] < 0:
            return None
        walk = int(found[0])
    ahead = middle[-1] - (middle[-2] if len(middle) > 1 else tip)
    if not np.hypot(*ahead) > 0:
        return None
    (line,) = integrate(domain, background, field,
                        [(middle[-1], ahead / np.hypot(*ahead), walk, corner)])
    return dataclasses.replace(line, points=np.vstack([tip, middle[:-1], line.points]))


def _midline(loop, tip, h) -> np.ndarray:
    """Points halfway between the two sides of the cusp at ``tip`` (segment, parameter),
    one every MIDLINE_STEP sizes of arc length along both, out to where the sides are
    MIDLINE_WIDTH sizes apart (at most HORN_SEARCH sizes out); empty where even the
    first pair is that far apart."""
    samples = int(round(HORN_SEARCH / MIDLINE_STEP))
    a, b, _ = _horn_sides(loop, tip, HORN_SEARCH * h, samples)
    keep = np.hypot(*(a - b).T) < MIDLINE_WIDTH * h
    count = int(np.argmin(keep)) if not keep.all() else len(keep)
    return 0.5 * (a[:count] + b[:count])


def _horn_reach(domain, background, node, size) -> float:
    """How far from a tangent horn's tip its two sides are HORN_WIDTH sizes apart (at
    most HORN_SEARCH sizes): a kite nearer the tip is a sliver between curves that
    part as the square of the distance, and its quads fold on the curved side."""
    corner = corner_endpoint(background, node)
    loop = domain.loops[corner.loop]
    a, b, along = _horn_sides(loop, (corner.segment, corner.param), HORN_SEARCH * size,
                              HORN_SAMPLES)
    wide = np.nonzero(np.hypot(*(a - b).T) >= HORN_WIDTH * size)[0]
    return float(along[wide[0]]) if len(wide) else HORN_SEARCH * size


def _horn_sides(loop, tip, distance, samples) -> tuple:
    """The points of the two sides leaving the tip (segment, parameter) at ``samples``
    equal steps out to ``distance`` along each, and those arc lengths."""
    sides = [_walk(loop, tip, step, distance, samples) for step in (1, -1)]
    a, b = (np.array([loop[seg].point(t) for seg, t, _ in side], dtype=float)
            for side in sides)
    return a, b, np.array([x[2] for x in sides[0]])


def _kite(domain, lines, k, which, reach) -> list:
    """Lines with line k stopped at the kite's inner corner, ``reach`` from the tip at
    its start (``which`` 0) or end (1), and the kite's arms added; unchanged where the
    kite does not fit (a line ends on the stretch it would cut off, or the nearest
    point of a side is the tip)."""
    line = lines[k]
    pts = np.asarray(line.points, dtype=float)
    towards_tip = pts if which else pts[::-1]
    tip_end = line.end if which else line.start
    cum = cumulative_length(towards_tip)
    total = float(cum[-1])
    kept = total - reach  # arc length of the line's part that stays, from its far end
    if reach <= 0.0 or kept <= 0.0:
        return lines
    for other in lines:
        if other.end.kind == "streamline" and other.end.index == k:
            s = other.end.param * total
            if (s if which else total - s) > kept:
                return lines  # a junction on the part that goes
    middle = point_at(towards_tip, cum, kept)
    stays = np.vstack([towards_tip[cum < kept], middle])
    loop = domain.loops[tip_end.loop]
    tip = (tip_end.segment, tip_end.param)
    sides = [_arm_end(loop, tip, step, middle, reach) for step in (1, -1)]
    if any(side is None for side in sides):
        return lines
    (seg_a, t_a, a), (seg_b, t_b, b) = sides
    arm_a = np.linspace(a, middle, ARM_POINTS + 1)
    arm_b = np.linspace(middle, b, ARM_POINTS + 1)
    arms = np.vstack([arm_a, arm_b[1:]])
    share = float(cumulative_length(arm_a)[-1] / cumulative_length(arms)[-1])
    junction = Endpoint("streamline", len(lines), param=share)
    out = list(lines)
    out[k] = dataclasses.replace(line, points=stays, end=junction) if which else \
        dataclasses.replace(line, points=stays[::-1], start=junction)
    shift = 0.0 if which else reach  # where the kept part starts along the old line
    for j, other in enumerate(out):  # junctions on line k: the same places, new fractions
        if other.end.kind == "streamline" and other.end.index == k:
            out[j] = dataclasses.replace(other, end=dataclasses.replace(
                other.end, param=(other.end.param * total - shift) / kept))
    out.append(Streamline(arms, Endpoint("boundary", -1, tip_end.loop, seg_a, t_a),
                          Endpoint("boundary", -1, tip_end.loop, seg_b, t_b)))
    return out


def _arm_end(loop, tip, step, middle, reach):
    """(segment, parameter, point) where an arm from ``middle`` meets the side that leaves
    the tip in direction ``step`` (+1 along the loop, -1 against it): the side's point
    nearest ``middle``, moved towards the tip so that the arm leans ARM_LEAN off the
    way back to the tip; None where the nearest point is the tip or lies past the
    stretch searched."""
    places = _walk(loop, tip, step, SEARCH * reach, SEARCH_SAMPLES)
    xy = np.array([loop[seg].point(t) for seg, t, _ in places])
    nearest = int(np.argmin(np.hypot(*(xy - middle).T)))
    if nearest == 0 or nearest == len(places) - 1:
        return None
    along = places[nearest][2]
    gap = float(np.hypot(*(xy[nearest] - middle)))
    back = min(gap / math.tan(ARM_LEAN), 0.5 * along)
    seg, t, _ = _walk(loop, tip, step, along - back, 1)[-1]
    return seg, t, loop[seg].point(t)


def _walk(loop, start, step, distance, samples) -> list:
    """(segment, parameter, arc length) at ``samples`` equal steps from ``start`` to
    ``distance`` along the loop in direction ``step``."""
    seg, t = start
    n = len(loop)
    if step < 0 and t <= 0.0:
        seg, t = (seg - 1) % n, 1.0
    if step > 0 and t >= 1.0:
        seg, t = (seg + 1) % n, 0.0
    out, covered = [], 0.0
    targets = np.linspace(0.0, distance, samples + 1)[1:] if samples > 1 else [distance]
    for target in targets:
        while True:
            length = loop[seg].length
            room = (1.0 - t if step > 0 else t) * length
            if target - covered <= room or length == 0.0:
                dt = (target - covered) / length if length else 0.0
                t_here = t + step * dt
                out.append((seg, float(np.clip(t_here, 0.0, 1.0)), float(target)))
                break
            covered += room
            seg = (seg + step) % n
            t = 0.0 if step > 0 else 1.0
    return out
