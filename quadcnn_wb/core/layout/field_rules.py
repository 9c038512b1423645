"""How a line follows the cross field: the rules every way of finding streamlines shares.

Three things walk along the field: numerical tracing (tracing.py, the reference), the
rebuild from network labels (infer/reconstruct.py, which traces numerically what it
cannot trust) and the coarse ray hints the network is given (infer/rays.py).  They march
differently on purpose (a quarter element per RK2 step, hops between labelled nodes,
whole-element steps of all rays at once), but they must agree on where separatrices
start, on the field between the nodes, on when a line has arrived at a singular point
or a concave corner, and on which of two lines along one separatrix is kept: otherwise
a rebuilt line ends elsewhere than the traced one and the partitions differ.  Those
rules live here, once.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy.spatial import cKDTree

from .crossings import cumulative_length
from .streamlines import Endpoint, Streamline

SNAP = 1.0  # snapping radius around singular points and concave corners, in element sizes
SNAP_ANGLE = math.radians(45)  # an approach must be this close to a separatrix to snap
MAX_LENGTH = 4.0  # streamlines longer than this many domain diagonals are capped
ROUND_TRIP = 3.0  # a line may end on its own source once it went this many SNAP radii
SNAP_CANDIDATES = 3  # a line is tested against this many nearest targets, nearest first
MERGE = 0.75  # a second line onto a taken separatrix joins it once this close (in sizes)
ARRIVAL_BLEND = 3.0  # an arriving line's last stretch (sizes) is bent onto the separatrix
ARRIVAL_REACH = 3.0  # which separatrix a line arrives along is judged over this (sizes)


# ----------------------------------------------------------------------------------------
# The field between the nodes


def cross_angle(z: np.ndarray, triangles: np.ndarray, tri: np.ndarray,
                bary: np.ndarray) -> np.ndarray:
    """One cross arm's angle (radians) at points inside triangles ``tri``, barycentric
    coordinates ``bary``: the nodes' z = exp(4it) interpolated linearly, a quarter of its
    argument.  Interpolating z, not the angles, is what makes the four arms agree: the
    nodes' angles may differ by quarter turns that mean the same cross."""
    return np.angle((z[triangles[tri]] * bary).sum(axis=1)) / 4.0


def nearest_arm(theta: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Unit vector of the cross arm (angle theta + k·90°) nearest to each direction d.

    A streamline keeps to the arm it travels along; the other three belong to the
    crossing family (two of them) and to going back."""
    a = np.arctan2(d[:, 1], d[:, 0])
    k = np.rint((a - theta) / (np.pi / 2))
    phi = theta + k * (np.pi / 2)
    out = np.empty((len(phi), 2))
    out[:, 0] = np.cos(phi)
    out[:, 1] = np.sin(phi)
    return out


# ----------------------------------------------------------------------------------------
# Where lines start and where they may end


def separatrix_sources(mesh, field, walker, h) -> list:
    """(start xy, unit direction, start triangle, start Endpoint) of every separatrix:
    each direction of each singular point, then each direction of each source corner.

    A corner's start triangle is the one the first step goes into: the corner node
    touches several, and the walk must begin in the one on the direction's side."""
    out = []
    for si, sing in enumerate(field.singularities):
        for k, d in enumerate(sing.directions):
            out.append((sing.xy, d, sing.triangle, Endpoint("singularity", si, branch=k)))
    incident = {}
    for t, tri in enumerate(mesh.triangles):
        for n in tri:
            incident.setdefault(int(n), []).append(t)
    for cs in field.corner_sources:
        tris = np.array(incident[cs.node])
        for branch, d in enumerate(cs.directions):
            out.append((cs.xy, d, start_triangle(walker, tris, cs.xy, d, h),
                        corner_endpoint(mesh, cs.node, branch)))
    return out


def start_triangle(walker, tris, xy, direction, h) -> int:
    """Of the triangles ``tris`` round a boundary node at ``xy``, the one a trace leaving
    it in ``direction`` goes into (the walk must begin on the direction's side)."""
    probe = np.repeat((xy + 1e-6 * h * direction)[None], len(tris), axis=0)
    return int(tris[np.argmax(walker.barycentric(tris, probe).min(axis=1))])


def corner_endpoint(mesh, node: int, branch: int = -1) -> Endpoint:
    """The Endpoint of a line leaving or reaching the boundary corner at ``node``."""
    k = int(np.nonzero(mesh.boundary_nodes == node)[0][0])
    return Endpoint("corner", int(node), int(mesh.boundary_loop[k]),
                    int(mesh.boundary_segment[k]), float(mesh.boundary_param[k]), branch)


def snap_targets(mesh, field) -> tuple[np.ndarray, list]:
    """((T, 2) places, their Endpoints) a line may end at: the singular points, then the
    source corners (branch left open: which separatrix it arrives along is decided on
    arrival)."""
    xy = [s.xy for s in field.singularities] + [c.xy for c in field.corner_sources]
    kind = [Endpoint("singularity", i) for i in range(len(field.singularities))]
    kind += [corner_endpoint(mesh, c.node) for c in field.corner_sources]
    return np.array(xy).reshape(-1, 2), kind


def may_snap(distance, before, own, corner, travelled, h):
    """Whether a line may end on a target ``distance`` away (``before``: that distance a
    step earlier): within SNAP sizes, closing in on it, and, when the target is the
    line's own source, only after going round (ROUND_TRIP) and never at a corner.

    Closing in, not merely near: a line leaving a singular point that happens to sit
    next to another must not end on it at once.  Elementwise on scalars or arrays."""
    near = np.logical_and(distance <= SNAP * h, distance < before)
    too_soon = np.logical_or(corner, travelled < ROUND_TRIP * SNAP * h)
    return np.logical_and(near, np.logical_not(np.logical_and(own, too_soon)))


def arrives_along(alignment):
    """Whether an approach whose direction has cosine ``alignment`` with a singular
    point's separatrix arrives along it (within SNAP_ANGLE).  In a dense layout (four
    holes) a line passing beside another singular point must not end there."""
    return alignment >= math.cos(SNAP_ANGLE)


# ----------------------------------------------------------------------------------------
# One line per separatrix


def claim_separatrices(lengths, starts, ends, joining=frozenset(), ties=None) -> tuple[list, dict]:
    """(indices of the lines to keep, sorted; {kept line: line holding its end slot}).

    A line from source a that arrives at b along b's separatrix k *is* that separatrix
    of b, so it claims two slots: ``starts[i]`` and ``ends[i]`` (None: it ends where no
    separatrix starts, on the boundary).  Shorter lines claim first, as a short
    connection between two singular points is the most trustworthy line.  A line whose
    start slot is still free but whose end slot is taken still stays (its own
    separatrix would be missing otherwise), joined to the line holding that slot.
    Lines in ``joining`` claim no end slot: kept, they are joined to its holder.
    ``ties``: a key per line that orders lines of equal length (else their order).
    """
    order = sorted(range(len(lengths)),
                   key=lambda i: (lengths[i], ties[i] if ties is not None else (), i))
    owner, keep, joins = {}, set(), {}
    for i in order:
        mine = {starts[i], None if i in joining else ends[i]} - {None}
        if not any(m in owner for m in mine):
            keep.add(i)
            owner.update({m: i for m in mine})
    for i in order:
        start, end = starts[i], ends[i]
        if i in keep:
            continue
        if start is not None and start not in owner:
            keep.add(i)
            owner[start] = i
            if end is not None and end in owner:
                joins[i] = owner[end]
    for i in sorted(set(joining) & keep):
        if owner.get(ends[i], i) != i:
            joins[i] = owner[ends[i]]
    return sorted(keep), joins


def one_line_per_separatrix(lines: list, h: float) -> list:
    """One streamline per separatrix (claim_separatrices).

    b's own trace of a separatrix that another line arrives along (which may have
    wandered elsewhere: tracing leaves a singular point less reliably than it arrives)
    goes; a line that has to stay although its end slot is taken ends on the line holding
    that slot where it meets it, as a T-junction, instead of piling a second line onto
    the same separatrix.  So does a line that came into a concave corner sideways
    (_sideways_into_corners): it holds no slot of the corner's.
    """
    def slot(e):
        return (e.kind, e.index, e.branch) if e.branch >= 0 else None

    lines = _along_own_separatrices(_arrival_branches(_ended_on_passed_points(lines, h), h), h)
    # Lengths equal but for round-off (a line from corner a to corner b and one from b to
    # a, three points each: held-out 0078 at diameter/100, whose turned copy kept the
    # other one) are equal, and the lower-numbered start claims first: corner nodes and
    # singular points are numbered alike in every pose, the traces are not ordered alike.
    final, joins = claim_separatrices([round(line.length / h, LENGTH_DIGITS) for line in lines],
                                      [slot(line.start) for line in lines],
                                      [slot(line.end) for line in lines],
                                      _sideways_into_corners(lines, h),
                                      [(line.start.place, line.end.place) for line in lines])
    position = {i: k for k, i in enumerate(final)}
    out = []
    for i in final:
        line = lines[i]
        if i in joins:
            line = _join(line, lines[joins[i]], position[joins[i]], h)
        out.append(line)
    return out


LENGTH_DIGITS = 6  # line lengths are compared in element sizes to this many decimals


def _sideways_into_corners(lines, h) -> set:
    """Lines that reach a concave corner along none of its own lines (seen ARRIVAL_REACH
    sizes back, more than SNAP_ANGLE off the nearest): they ran beside one of the
    corner's sides into it.  Such a line is no trace of the corner's line and does not
    take its place; it ends on it, a T-junction, as a second line onto a taken slot
    does.  (Held-out 0058: a separatrix 0.65 of a size above a slot's edge was read as
    arriving along the corner's line up, 75 degrees off it; the shorter separatrix
    claimed that line's slot, the corner's line went, and the face between the
    separatrix and the edge had three corners: split round a centre, worst 0.22.)"""
    leaving = {(ln.start.kind, ln.start.index, ln.start.branch): ln for ln in lines}
    out = set()
    for k, line in enumerate(lines):
        end = line.end
        own = leaving.get((end.kind, end.index, end.branch))
        if end.kind != "corner" or own is None or own is line:
            continue
        coming = heading(line.points[::-1], ARRIVAL_REACH * h)
        if coming.any() and not arrives_along(
                float(coming @ heading(own.points, ARRIVAL_REACH * h))):
            out.add(k)
    return out


def _ended_on_passed_points(lines, h):
    """A separatrix that passes another singular point within PASSED_MISS sizes, heading
    back along that point's separatrix which came to its own point, ends there too.

    The two are one separatrix traced from both ends: one trace snapped onto the other
    point, and the other missed by more than the snap radius (on a background finer
    than the mesh, by most of a quad), ran on beside it and was cut where it met other
    lines; the strip between the two was no block (a blend test plate: 30 % of its quads
    unstructured).  Ended on the point it passed, it holds the same two slots as the
    other, and one of them goes (claim_separatrices)."""
    sources = [k for k, line in enumerate(lines)
               if line.start.kind == "singularity" and len(line.points) > 2]
    out = list(lines)
    for k in sources:
        line = lines[k]
        if line.end.kind in ("singularity", "corner"):
            continue
        passes = []
        for j in sources:
            other = lines[j]
            if other.start.index == line.start.index or other.end.kind != "singularity" \
                    or other.end.index != line.start.index:
                continue
            hit = _near_pass(line, other, h)
            if hit is not None:
                passes.append((hit[0], hit[1], j))
        if passes:
            cut, _, j = min(passes)  # the first point it passes
            # Bent onto the point over its last stretch, not kinked at the nearest pass.
            out[k] = dataclasses.replace(
                line, points=bent_to(line.points[:cut + 1], lines[j].points[0],
                                     ARRIVAL_BLEND * h),
                end=Endpoint("singularity", lines[j].start.index, branch=lines[j].start.branch))
    return out


PASSED_MISS = 3.0  # sizes: a separatrix passing another singular point this close ...
PASSED_ANGLE = math.radians(45)  # ... heading back along that point's separatrix this close


def _near_pass(line, other, h):
    """(index of line's point nearest other's singular point on its first pass within
    PASSED_MISS sizes, that distance), when the line there heads back along other's
    separatrix; None otherwise."""
    target = other.points[0]
    dist = np.hypot(*(line.points - target).T)
    within = np.nonzero(dist[1:] <= PASSED_MISS * h)[0] + 1
    if not len(within):
        return None
    first = int(within[0])
    away = np.nonzero(dist[first:] > PASSED_MISS * h)[0]
    run_end = first + int(away[0]) if len(away) else len(dist)  # the first pass ends
    nearest = first + int(np.argmin(dist[first:run_end]))
    if nearest == 0 or nearest >= len(line.points) - 1:
        return None
    back = heading(line.points[nearest::-1], h)  # where the line came from, seen there
    leaving = heading(other.points, ARRIVAL_REACH * h)
    if float(back @ leaving) < math.cos(PASSED_ANGLE):
        return None
    return nearest, float(dist[nearest])


def _arrival_branches(lines, h):
    """Which separatrix of its end point (singular point or concave corner) each arriving
    streamline runs along.

    The direction of arrival alone is ambiguous next to a singular point (the field turns
    fast there, and a snap's last step runs straight at the point from up to a size
    away), so the line is seen from the point ARRIVAL_REACH sizes back along it and each
    of the point's own traced separatrices as far out: it arrives along the one whose
    heading is nearest its own.  (Distances between the polylines told them apart
    poorly: a line half a size beside a separatrix was as far from it, on average, as
    from a short separatrix to the nearby boundary, all of whose points lie near the
    point; and a line a size beside one was as far from either side of a corner.)
    """
    leaving = {(ln.start.kind, ln.start.index, ln.start.branch): ln for ln in lines}
    out = []
    for line in lines:
        end = line.end
        if not any(key[:2] == (end.kind, end.index) for key in leaving):
            out.append(line)  # the boundary, or a convex corner: no separatrices there
            continue
        own_traces = [(branch, own) for (kind, index, branch), own in leaving.items()
                      if (kind, index) == (end.kind, end.index) and len(own.points) > 1]
        coming = heading(line.points[::-1], ARRIVAL_REACH * h)
        if not coming.any():
            # No length, no heading (a corner's trace that left the domain at once): it
            # arrives along none of the point's separatrices.  Every cosine would be 0,
            # and the first branch in the point's numbering, which a mirror image
            # reverses, would have been its slot, taken from the line that runs there.
            out.append(line)
            continue
        best, best_cos = end.branch, -np.inf
        for branch, own in own_traces:
            cos = float(coming @ heading(own.points, ARRIVAL_REACH * h))
            if cos > best_cos:
                best, best_cos = branch, cos
        out.append(dataclasses.replace(line, end=dataclasses.replace(end, branch=best)))
    return out


def heading(points, reach):
    """Unit direction from a polyline's first point to its point ``reach`` along it (two
    thirds of its length where it is shorter): where it heads, seen from that point."""
    cum = cumulative_length(points)
    reach = min(reach, 2.0 * cum[-1] / 3.0)
    d = np.array([np.interp(reach, cum, points[:, 0]),
                  np.interp(reach, cum, points[:, 1])]) - points[0]
    n = float(np.hypot(*d))
    return d / n if n > 0 else d


def _along_own_separatrices(lines, h):
    """Arriving lines whose last stretch is bent onto the separatrix they arrive along.

    A line snaps onto a point from up to SNAP sizes away, beside the separatrix rather
    than on it, and its last step then ran straight at the point with a kink of up to a
    right angle; the faces on either side measured their turn at the point from that
    kink, not from the separatrix, and one of them lost (or gained) a corner.  Over its
    last ARRIVAL_BLEND sizes the line is blended into the point's own trace of that
    separatrix (matched by distance from the point, weights rising smoothly to one at
    the point), so it arrives along it, as a streamline into a singular point does."""
    leaving = {(ln.start.kind, ln.start.index, ln.start.branch): ln for ln in lines}
    out = []
    for line in lines:
        own = leaving.get((line.end.kind, line.end.index, line.end.branch))
        if own is None or own is line or line.end.branch < 0 \
                or not _leave_alike(line.points[::-1], own.points, h):
            out.append(line)  # no such trace, or one off to another side: left as it is
            continue
        out.append(dataclasses.replace(line, points=_blended_tail(line.points, own.points,
                                                                  ARRIVAL_BLEND * h)))
    return out


ALIKE = math.cos(math.radians(60))  # two lines leaving a point this close run alike
ALIKE_REACH = 2.0  # ... seen this many sizes out


def _leave_alike(first, second, h) -> bool:
    """Whether two polylines leaving one point head the same way, seen from the point
    ALIKE_REACH sizes out (or two thirds of their length): a line is bent onto a
    separatrix only when it comes in beside it, never round to another side of the
    point.  Farther out than the snap's last step, whose kink points anywhere."""
    return float(heading(first, ALIKE_REACH * h) @ heading(second, ALIKE_REACH * h)) >= ALIKE


def _blended_tail(points, own, reach):
    """``points`` (ending at own[0]) with the last ``reach`` of it moved onto ``own``.

    Every point moves by its own weight, a smooth function of its distance along the
    line to the end (zero beyond ``reach``): no point is picked by an index, so a turned
    or moved copy of the part gets the same line to round-off."""
    cum, own_cum = cumulative_length(points), cumulative_length(own)
    reach = min(reach, 0.5 * float(cum[-1]), 0.5 * float(own_cum[-1]))
    if reach <= 0:
        return points
    from_end = cum[-1] - cum  # distance along the line to the point
    target = np.column_stack([np.interp(from_end, own_cum, own[:, 0]),
                              np.interp(from_end, own_cum, own[:, 1])])
    w = tail_weights(from_end, reach)[:, None]
    moved = (1.0 - w) * points + w * target
    moved[-1] = points[-1]
    return moved


def tail_weights(from_end, reach) -> np.ndarray:
    """How far each point of a line's last ``reach`` moves with its end: rising smoothly
    (smoothstep) from 0 at ``reach`` to 1 at the end, by arc length ``from_end``."""
    x = np.clip(1.0 - np.asarray(from_end, dtype=float) / reach, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def shifted_tail(path, shift, reach) -> list:
    """The path with its end moved by ``shift`` and the stretch before it by less and
    less, to nothing ``reach`` back along it.

    An exit moved onto a nearby corner (CORNER_SNAP) by its last point alone came in
    with a kink of up to a right angle, and the faces either side measured their turn
    at the corner from the kink: one lost its corner there (a T-slot's 225° notch: a
    three-cornered face, split round an extra irregular vertex).  Weights are a smooth
    function of arc length to the end, so a turned copy gets the same line; the reach is
    at most half the line, whose start stays where it is."""
    if not np.any(shift):
        return path
    points = np.asarray(path, dtype=float)
    cum = cumulative_length(points)
    reach = min(reach, 0.5 * float(cum[-1]))  # the start stays where it is
    if reach <= 0:
        return path
    return list(points + tail_weights(cum[-1] - cum, reach)[:, None] * shift)


def bent_to(points, place, reach) -> np.ndarray:
    """``points`` ending exactly at ``place``, the stretch before the end bent there
    smoothly over ``reach`` (shifted_tail)."""
    points = np.asarray(points, dtype=float)
    bent = np.asarray(shifted_tail(points, np.asarray(place) - points[-1], reach), dtype=float)
    bent[-1] = place
    return bent


def _join(line: Streamline, other: Streamline, other_index: int, h: float) -> Streamline:
    """End ``line`` on ``other`` where it first comes within MERGE sizes of it.  Where
    both leave or reach one point (a singular point's two separatrices that end on the
    same slot), not in the stretch where it is still leaving that point: joined there,
    it kept no length and its separatrix was lost (crankshaft_web_keyway's keyway: a
    valence-3 point with two lines, the face beside it turning back)."""
    dense = _densify(other.points, 0.25 * h)
    dist = cKDTree(dense).query(line.points)[0]
    near = dist <= MERGE * h
    if line.start.same_place(other.start) or line.start.same_place(other.end):
        away = np.nonzero(~near)[0]
        if not len(away):
            return line
        near[:away[0]] = False
    close = np.nonzero(near)[0]
    close = close[close > 0]
    if not len(close):
        return line
    head = int(close[0])
    point, param = nearest_on_polyline(other.points, line.points[head])
    return dataclasses.replace(line, points=np.vstack([line.points[:head], point]),
                               end=Endpoint("streamline", other_index, param=param))


def _densify(points, spacing):
    seg = np.diff(points, axis=0)
    n = np.maximum(1, np.ceil(np.hypot(seg[:, 0], seg[:, 1]) / spacing).astype(int))
    parts = [points[i] + np.outer(np.arange(k) / k, seg[i]) for i, k in enumerate(n)]
    return np.vstack(parts + [points[-1:]])


def nearest_on_polyline(points, p):
    """Closest point to p on the polyline, and its arc-length fraction along it."""
    a, b = points[:-1], points[1:]
    d = b - a
    len2 = np.maximum((d * d).sum(axis=1), 1e-300)
    t = np.clip(((p - a) * d).sum(axis=1) / len2, 0.0, 1.0)
    q = a + t[:, None] * d
    k = int(np.argmin(np.hypot(*(q - p).T)))
    seglen = np.sqrt(len2)
    total = float(seglen.sum())
    along = float(seglen[:k].sum() + t[k] * seglen[k])
    return q[k], along / total if total > 0 else 0.0
