"""Three-, five- and six-cornered faces of a partition, split into quadrilateral blocks.

Near an acute corner (under 45°, a quarter-turn count of 0) or where singular points
nearly coincide, a face of the streamline arrangement can come out with 3 or 5 corners.
Midpoint subdivision turns a k-cornered face into k blocks meeting at its centre: every
side is cut at its middle (the neighbouring block just gets a T-junction there) and joined
to the centre.  The centre becomes one extra irregular vertex (valence k), which is the
price of a block-structured mesh there.  A six-cornered face (when the partition is
asked for it: the last resort, see partition.build_partition) is instead cut straight
between two opposite corners into two blocks, an extra edge at each end of the cut.  A
five- or six-cornered face too concave for either is cut from corners to sides where
such cuts stay inside it (peel.py); only what none of these splits stays a free face
(unstructured quads, see free_faces.py).

The last resort also splits round a centre what would otherwise stay free: a six-cornered
face with no such cut, faces of up to eight corners, and faces with reflex corners (a
trace dropped, a singular point's sector left open).  A reflex corner takes a side middle's
place as a spoke's end: the spoke halves its angle, so that each block still has one of
the face's convex corners, two spoke ends and the centre (no side next to a reflex corner
is cut; two reflex corners side by side leave no block between them, so such a face stays
free).  Every spoke must then lie inside the face.
"""

from __future__ import annotations

import numpy as np

from .crossings import cumulative_length, point_at
from .face_geometry import ccw_angle, segment_inside, side_of
from .partition_types import (
    Block,
    BoundaryPiece,
    Edge,
    FreeFace,
    PartitionError,
    fmt,
    inside_polygon,
    pieces_length,
)
from .peel import peel_plan, pieces

MIDPOINT_SNAP = 0.25  # use an existing side vertex this close to the middle (share of side)


def split_key(vertices, corners) -> tuple:
    """The name of an odd face's split (its spokes' origin): its corner places, which a
    rebuild of the same input repeats exactly."""
    return ("split", frozenset(tuple(np.asarray(vertices[c]).tolist()) for c in corners))


def split_odd_faces(vertices: list, edges: list, faces: list, free: list, domain,
                    unsplit=frozenset(), star=False):
    """(vertex list, blocks, free faces): four-cornered faces as they are, others
    subdivided; free faces follow the edges split on their way.  A face whose split is
    in ``unsplit`` (its blocks became a free face that could not be filled: the spokes
    are what a rebuild can take away) stays whole, a free face.  ``star`` (the last
    resort): a six-cornered face with no cut is split round a centre too, and so is a
    face with reflex corners (see _star_targets)."""
    vertices = list(vertices)
    blocks = []
    free_halves = [(list(f.halves), f.reason) for f in free]
    everything = [(face[0], face[1]) for face in faces] \
        + [(None, [halves]) for halves, _ in free_halves]
    # Six-cornered faces are cut between two opposite corners first (no centre, no new
    # side middles): their cut is decided on the sides as they are now, which the other
    # faces' splits only subdivide.
    halved, odd, peeled = [], [], []
    for face in faces:
        corners, sides, reflex = face
        if len(corners) == 6 and not reflex:
            key = split_key(vertices, corners)
            at = None if key in unsplit else _opposite_corners(vertices, edges, corners, sides)
            if at is not None:
                halved.append((corners, sides, at, key))
            elif star and key not in unsplit:
                odd.append((corners, sides, reflex))
            elif key not in unsplit and (plan := _peel_plan(vertices, edges, corners,
                                                             sides)) is not None:
                peeled.append((corners, sides, plan, key))
            else:
                why = "whose split could not be filled" if key in unsplit \
                    else "has no cut into two quadrilaterals"
                centre = np.mean([vertices[c] for c in corners], axis=0)
                halves = [h for side in sides for h in side]
                free_halves.append((halves, f"a 6-cornered block near {fmt(centre)} {why}"))
                everything.append((None, [halves]))
        elif len(corners) != 4 or reflex:
            odd.append((corners, sides, reflex))
    # Every side's middle first: a later face's split cuts an edge of an earlier face's
    # side too, and that face's blocks must be made from its sides as finally cut.  A
    # side's middle may be a vertex an earlier face's split made, so the faces go in an
    # order a turned, moved or mirrored copy shares (nist_ctc02_logo_plate at
    # diameter/100: its mirror image split two touching faces the other way round, one
    # middle moved by a tenth of an element, and the counts went another way): the
    # largest first, whose middles the smaller ones beside them then share
    # (nist_ctc04_plate at its default size is all blocks that way, not the other).
    odd.sort(key=lambda face: _place_key(vertices, face[0]))
    holders = _sides_holding(everything)
    all_mids = [[None if _next_to_reflex(j, len(corners), reflex)
                 else _split_side(vertices, edges, holders, sides, j, domain)
                 for j in range(len(sides))] for corners, sides, reflex in odd]
    # Where no centre sees a face's sides, straight cuts from corners to sides may still
    # make it blocks (peel.py); their feet split sides too, so every such split comes
    # before any block is made.
    decided = []
    for (corners, sides, reflex), mids in zip(odd, all_mids):
        k = len(corners)
        targets = [mids[j] if mids[j] is not None else corners[(j + 1) % k]
                   for j in range(k) if j not in reflex]  # after each convex corner
        convex = [corners[j] for j in range(k) if j not in reflex]
        centre = np.mean([vertices[t] for t in targets] + [vertices[c] for c in convex],
                         axis=0)
        key = split_key(vertices, corners)
        outline = np.vstack([_side_points(side, edges)[:-1] for side in sides])
        if key not in unsplit and not _centre_sees(vertices, outline, corners, reflex,
                                                   centre, targets) \
                and (reflex or k >= 6):
            # The mean of a concave face's corners may not see them all; the middle of
            # the face's kernel (what sees all of its outline) does where there is one.
            kernel = _kernel(outline)
            if kernel is not None:
                centre = kernel
        if key not in unsplit:
            centre = _centre_inside(vertices, outline, centre, targets, convex)
        if key in unsplit or not _centre_sees(vertices, outline, corners, reflex, centre,
                                              targets):
            plan = None if key in unsplit or reflex else \
                _peel_plan(vertices, edges, corners, sides)
            if plan is not None:
                peeled.append((corners, sides, plan, key))
                decided.append(("peeled",))
                continue
            why = "whose split could not be filled" if key in unsplit \
                else "is too concave to split into quadrilaterals"
            decided.append(("free", f"a {k}-cornered block near {fmt(centre)} {why}"))
            continue
        decided.append(("star", centre, targets))
    peel_blocks = [block for corners, sides, plan, key in peeled
                   for block in _peel(vertices, edges, holders, corners, sides, plan, key,
                                      domain)]
    for (corners, sides, reflex), mids, decision in zip(odd, all_mids, decided):
        if decision[0] == "peeled":  # its blocks are in peel_blocks
            continue
        if decision[0] == "free":
            halves = [h for side in sides for h in side]
            free_halves.append((halves, decision[1]))
            everything.append((None, [halves]))
            continue
        k = len(corners)
        _, centre, targets = decision
        c_id = len(vertices)
        vertices.append(centre)
        spoke = {}
        for t in targets:
            spoke[t] = len(edges)
            edges.append(Edge(points=np.linspace(centre, vertices[t], 8), a=c_id, b=t,
                              origin=key))
        for j in range(k):
            if j in reflex:
                continue
            prev = (j - 1) % k
            # From corner j to the target after it (side j's middle, or the reflex corner
            # that ends side j), and from the target before it (side prev's middle, or the
            # reflex corner that starts side prev) back to corner j.
            if mids[j] is not None:
                to_next, after = sides[j][: _mid_index(sides[j], edges, mids[j]) + 1], mids[j]
            else:
                to_next, after = sides[j], corners[(j + 1) % k]
            if mids[prev] is not None:
                from_prev = sides[prev][_mid_index(sides[prev], edges, mids[prev]) + 1:]
                before = mids[prev]
            else:
                from_prev, before = sides[prev], corners[prev]
            blocks.append(Block(corners=(corners[j], after, c_id, before),
                                sides=(tuple(to_next), ((spoke[after], False),),
                                       ((spoke[before], True),), tuple(from_prev))))
    for corners, sides, at, key in halved:
        blocks.extend(_halves_of_hexagon(vertices, edges, corners, sides, at, key))
    blocks.extend(Block(corners=tuple(c), sides=tuple(tuple(side) for side in s))
                  for c, s in peel_blocks)
    for face in faces:
        if len(face[0]) == 4 and not face[2]:
            blocks.append(Block(corners=tuple(face[0]),
                                sides=tuple(tuple(s) for s in face[1])))
    return vertices, blocks, [FreeFace(tuple(h), reason) for h, reason in free_halves]


def _place_key(vertices, corners) -> tuple:
    """What every copy of the part sees alike in the layout frame (whose mirror image
    negates x): the area of a face's corner polygon, largest first, then the mean of its
    corners, y then |x|; rounded well above round-off."""
    p = np.array([vertices[c] for c in corners], dtype=float)
    area = 0.5 * abs(float(np.sum(p[:, 0] * np.roll(p[:, 1], -1)
                                  - np.roll(p[:, 0], -1) * p[:, 1])))
    x, y = p.mean(axis=0)
    return (-round(area, PLACE_DIGITS), round(float(y), PLACE_DIGITS),
            round(abs(float(x)), PLACE_DIGITS))


PLACE_DIGITS = 9  # of the layout frame's unit coordinates


def _next_to_reflex(j: int, k: int, reflex) -> bool:
    """Whether side j (from corner j to corner j + 1 of k) has a reflex corner at an end:
    that corner is its block's target, so the side gets no middle."""
    return j in reflex or (j + 1) % k in reflex


def _kernel(outline):
    """The mean of the vertices of a counter-clockwise outline's kernel (the points that see
    all of it: inside every edge's left half-plane), or None where it is empty."""
    lo, hi = outline.min(axis=0), outline.max(axis=0)
    poly = np.array([lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]], dtype=float)
    nxt = np.roll(outline, -1, axis=0)
    scale = float(np.hypot(*(hi - lo)))
    for a, b in zip(outline, nxt):
        if np.hypot(*(b - a)) <= 1e-12 * scale:
            continue
        side = side_of(a, b, poly)
        keep = side >= 0.0
        if keep.all():
            continue
        if not keep.any():
            return None
        out = []
        for i in range(len(poly)):
            j = (i + 1) % len(poly)
            if keep[i]:
                out.append(poly[i])
            if keep[i] != keep[j]:
                f = side[i] / (side[i] - side[j])
                out.append(poly[i] + f * (poly[j] - poly[i]))
        poly = np.array(out)
        if len(poly) < 3:
            return None
    return poly.mean(axis=0)


def _centre_sees(vertices, outline, corners, reflex, centre, targets) -> bool:
    """Whether the spokes from the centre can go in: the centre inside the corners'
    polygon, and (in a face with reflex corners or more than six) every spoke inside the
    face's ``outline``."""
    if not inside_polygon(np.array([vertices[c] for c in corners]), centre):
        return False
    return (not reflex and len(corners) < 6) or _spokes_inside(vertices, outline, centre,
                                                                targets)


def _spokes_inside(vertices, outline, centre, targets) -> bool:
    return all(segment_inside(outline, centre, np.asarray(vertices[t])) for t in targets)


CENTRE_SHIFTS = (0.25, 0.5)  # of the way from the centre to a corner or target, tried


def _centre_inside(vertices, outline, centre, targets, convex) -> np.ndarray:
    """``centre``, or where its spokes would leave the face (a side that is a boundary
    curve bulging in: held-out 0095's 8192-node layout had a five-cornered face's centre
    beside such a curve, a spoke across it, and the block's map folded) the nearest point
    whose spokes stay inside, tried a quarter and half of the way to each corner and
    target (nearest first, by distances rounded well above round-off, which every pose
    shares); ``centre`` as it was where none is."""
    def sees(point) -> bool:
        return inside_polygon(outline, point) and _spokes_inside(vertices, outline, point,
                                                                 targets)

    if sees(centre):
        return centre
    scale = float(np.hypot(*(outline.max(axis=0) - outline.min(axis=0))))
    tries = []
    for shift in CENTRE_SHIFTS:
        for v in list(convex) + list(targets):
            point = centre + shift * (np.asarray(vertices[v], dtype=float) - centre)
            spread = sum(float(np.hypot(*(point - np.asarray(vertices[t])))) for t in targets)
            tries.append((round(shift, 9), round(spread / scale, 9), len(tries), point))
    for *_, point in sorted(tries, key=lambda entry: entry[:3]):
        if sees(point):
            return point
    return centre


MIN_CUT_ANGLE = np.radians(30.0)  # the least angle a hexagon's cut may leave at a corner


def _opposite_corners(vertices, edges, corners, sides):
    """Which corner k of a six-cornered face to join to corner k + 3 (None: no cut stays
    inside the face with every angle it makes at least MIN_CUT_ANGLE).

    Two blocks either side of one straight cut, where a midpoint split would put a
    valence-6 vertex in the middle: the cut's ends get one more edge each, nothing else
    changes.  The cut leaving the widest least angle wins (a tie, in a symmetric face,
    goes to the first of the face's corners).  A face's sides seen from a corner are
    measured a quarter of their length on, so a kink at a corner does not decide."""
    outline = np.vstack([_side_points(side, edges)[:-1] for side in sides])
    best, best_angle = None, MIN_CUT_ANGLE
    for k in range(3):
        a, b = np.asarray(vertices[corners[k]]), np.asarray(vertices[corners[k + 3]])
        if not segment_inside(outline, a, b):
            continue
        angle = min(min(_split_angles(edges, sides, k, b - a)),
                    min(_split_angles(edges, sides, k + 3, a - b)))
        if angle > best_angle + 1e-9:
            best, best_angle = k, angle
    return best


def _split_angles(edges, sides, k, cut) -> tuple:
    """The two angles a cut along ``cut`` makes at corner k with the face's sides there
    (counter-clockwise from the side leaving k, then on to the side arriving)."""
    leaving = _side_points(sides[k], edges)
    arriving = _side_points(sides[k - 1], edges)[::-1]
    out = _heading(leaving)
    back = _heading(arriving)
    return ccw_angle(out, cut), ccw_angle(cut, back)


def _heading(points) -> np.ndarray:
    """Direction from a polyline's start to its point a quarter of its length on."""
    cum = cumulative_length(points)
    return point_at(points, cum, 0.25 * float(cum[-1])) - points[0]


def _halves_of_hexagon(vertices, edges, corners, sides, k, key) -> list:
    """The two blocks of a six-cornered face cut from corner k to corner k + 3."""
    a, b = corners[k], corners[k + 3]
    cut = len(edges)
    edges.append(Edge(points=np.linspace(vertices[a], vertices[b], 8), a=a, b=b, origin=key))
    first = Block(corners=tuple(corners[k:k + 4]),
                  sides=tuple(tuple(s) for s in sides[k:k + 3]) + (((cut, False),),))
    rest = [corners[(k + 3 + j) % 6] for j in range(4)]
    second = Block(corners=tuple(rest),
                   sides=tuple(tuple(sides[(k + 3 + j) % 6]) for j in range(3)) + (((cut, True),),))
    return [first, second]


def _head(edges, half):
    e, forward = half
    return edges[e].b if forward else edges[e].a


def _mid_index(side, edges, vertex):
    """Index in side of the half-edge that ends at vertex."""
    for i, half in enumerate(side):
        if _head(edges, half) == vertex:
            return i
    raise PartitionError("lost a side's midpoint while splitting a block")


def _side_points(side, edges):
    pts = []
    for e, forward in side:
        p = edges[e].points if forward else edges[e].points[::-1]
        pts.extend(p if not pts else p[1:])
    return np.array(pts)


def _sides_holding(faces) -> dict:
    """Edge id -> the side lists (of ``faces``: (corners, sides) pairs) it lies on, each
    once: a split edge's halves are replaced there alone.  Looking through every face
    for each split cost a knurled ring's 4352 splits 12 s."""
    out: dict = {}
    for _, sides in faces:
        for side in sides:
            _hold(out, side)
    return out


def _hold(holders, side) -> None:
    """Register a side list under each edge it holds (once per edge)."""
    for e in dict.fromkeys(e for e, _ in side):
        holders.setdefault(e, []).append(side)


def _peel_plan(vertices, edges, corners, sides):
    """peel.peel_plan on a face's corners and sides as polylines."""
    return peel_plan([vertices[c] for c in corners],
                     [_side_points(side, edges) for side in sides])


def _peel(vertices, edges, holders, corners, sides, plan, key, domain) -> list:
    """The (corners, sides) of the quadrilaterals a face's peel plan cuts it into; each
    foot splits its side (and whatever else holds that edge, through ``holders``), each
    cut is an edge whose origin is the face's split key (a rebuild can take it away)."""
    corners, sides = list(corners), list(sides)
    quads = []
    for c, j, s, snap in plan:
        foot = _split_at(vertices, edges, holders, sides[j], s, snap, domain)
        i = _mid_index(sides[j], edges, foot)
        first, second = sides[j][: i + 1], sides[j][i + 1:]
        cut = len(edges)
        edges.append(Edge(points=np.linspace(vertices[corners[c]], vertices[foot], 8),
                          a=corners[c], b=foot, origin=key))
        out, back = [(cut, True)], [(cut, False)]
        for side in (first, second, out, back):
            _hold(holders, side)
        quad_corners, quad_sides, corners, sides = pieces(corners, sides, c, j, foot, first,
                                                          second, out, back)
        quads.append((quad_corners, quad_sides))
    quads.append((corners, sides))
    return quads


def _split_at(vertices, edges, holders, side, s, snap, domain) -> int:
    """Vertex id at arc length ``s`` of a side's polyline (its edges' points): an inner
    vertex of the side within ``snap`` of it, else a new one splitting its edge."""
    lengths = np.array([float(cumulative_length(edges[e].points)[-1]) for e, _ in side])
    return _vertex_along(vertices, edges, holders, side, lengths, s, snap, domain)


def _split_side(vertices, edges, holders, sides, j, domain) -> int:
    """Vertex id in the middle of side j (an existing one, or a new one from a split);
    ``holders``: _sides_holding's map, kept up to date."""
    lengths = np.array([edges[e].length for e, _ in sides[j]])
    total = float(lengths.sum())
    return _vertex_along(vertices, edges, holders, sides[j], lengths, total / 2,
                         MIDPOINT_SNAP * total, domain)


def _vertex_along(vertices, edges, holders, side, lengths, s, snap, domain) -> int:
    """Vertex id at ``s`` along a side whose half-edges measure ``lengths``: an inner
    vertex within ``snap``, else a new one splitting the half-edge holding it (and every
    side that holds that edge, through ``holders``)."""
    ends = np.cumsum(lengths)
    inner = ends[:-1]
    if len(inner):
        k = int(np.argmin(np.abs(inner - s)))
        if abs(inner[k] - s) <= snap:
            return _head(edges, side[k])
    k = min(int(np.searchsorted(ends, s)), len(side) - 1)
    e, forward = side[k]
    along = s - (ends[k] - lengths[k])
    at = along if forward else lengths[k] - along  # from the edge's start, in ``lengths``
    if lengths[k] != edges[e].length:  # a polyline's measure: the edge's own along it
        at = min(max(at / max(lengths[k], 1e-300), 0.0), 1.0) * edges[e].length
    new_vertex, tail = _split_edge(vertices, edges, e, at, domain)
    for other in holders.get(e, ()):
        _replace_half(other, e, tail)
    holders[tail] = list(holders.get(e, ()))
    return new_vertex


def _replace_half(side, e, tail):
    i = 0
    while i < len(side):
        edge, forward = side[i]
        if edge == e:
            side[i:i + 1] = [(e, True), (tail, True)] if forward else [(tail, False), (e, False)]
            i += 2
        else:
            i += 1


def _split_edge(vertices, edges, e, s, domain):
    """Cut edge e at arc length s; e keeps the first part, a new edge the rest."""
    edge = edges[e]
    pts = edge.points
    cum = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])
    if edge.is_boundary:
        first, second, point = _split_pieces(edge.pieces, s, domain)
    else:
        first = second = ()
        k = int(np.clip(np.searchsorted(cum, s) - 1, 0, len(pts) - 2))
        f = (s - cum[k]) / max(cum[k + 1] - cum[k], 1e-300)
        point = pts[k] + f * (pts[k + 1] - pts[k])
    v = len(vertices)
    vertices.append(np.asarray(point, dtype=float))
    before = pts[cum < s]
    after = pts[cum > s]
    exact = (pieces_length(domain, first), pieces_length(domain, second)) \
        if edge.is_boundary else (-1.0, -1.0)
    edges[e] = Edge(points=np.vstack([before, point]), a=edge.a, b=v, pieces=first,
                    streamline=edge.streamline, origin=edge.origin, exact_length=exact[0])
    edges.append(Edge(points=np.vstack([point, after]), a=v, b=edge.b, pieces=second,
                      streamline=edge.streamline, origin=edge.origin, exact_length=exact[1]))
    return v, len(edges) - 1


def _split_pieces(pieces, s, domain):
    """Split exact boundary stretches at arc length s: (first, second, point)."""
    remaining = s
    for i, p in enumerate(pieces):
        curve = domain.loops[p.loop][p.segment]
        length = curve.length * abs(p.t1 - p.t0)
        if remaining <= length or i == len(pieces) - 1:
            t = p.t0 + (p.t1 - p.t0) * min(max(remaining / length, 0.0), 1.0)
            first = tuple(pieces[:i]) + (BoundaryPiece(p.loop, p.segment, p.t0, t),)
            second = (BoundaryPiece(p.loop, p.segment, t, p.t1),) + tuple(pieces[i + 1:])
            return first, second, curve.point(t)
        remaining -= length
    raise PartitionError("could not split a boundary edge")
