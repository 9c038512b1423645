"""Block partition: the planar arrangement of boundary curves and streamlines, and its
faces checked to be four-sided blocks.

Vertices are the loop vertices, singular points, streamline ends on the boundary, crossings
of streamlines and T-junctions; edges are the boundary and streamline pieces between them
(boundary pieces remember their exact curve stretch, so mesh nodes can go on the true
curve).  Faces are walked with half-edges, the face on the left of each.  A block corner
is a vertex where the face's boundary turns by more than 45° (about 90° on a field-aligned
partition); a straight-through vertex (a T-junction, a streamline foot) only splits a side
into several edges.  A loop that no streamline reaches (an annulus's hole) first gets a
cut along a field line, so every face is a disk.  A face with other than four corners or
with a reflex turn is no block: it is kept as a free face with the reason (the mesh builder
fills it with unstructured quads that conform to the blocks around it, free_faces.py), so
one bad face no longer costs the whole domain its blocks.  Only what breaks the arrangement
itself (a zero-length edge, a walk that never closes) is a PartitionError.
"""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np

from ..input.corners import interior_angle
from ..input.features import is_smooth_join
from .crossings import crossings, cumulative_length, end_places, point_at, resampled
from .partition_types import (
    BoundaryPiece,
    Edge,
    FreeFace,
    Partition,
    PartitionError,
    fmt,
    halves_outline,
    inside_polygon,
    pieces_length,
    polygon_area,
    signed_area,
)
from .subdivide import split_odd_faces

TURN_TIE = 1e-6  # radians: turns this close to CORNER_TURN are exactly at it
CORNER_TURN = math.radians(45)  # a face turning more than this at a vertex has a corner there
PROMOTED_TURN = math.radians(15)  # a three-cornered face's fourth corner bends at least this
# (tailwheel_gusset's spike ends in a slightly curved chamfer: 16.6° at its upper end)
# The last resort (build_partition's ``last_resort``): faces of up to this many corners,
# and faces with reflex corners that turn back by at most STAR_REFLEX, are split round a
# centre (subdivide.py) instead of being left free.
STAR_CORNERS = 8
STAR_REFLEX = math.radians(135)


# ----------------------------------------------------------------------------------------
# Building the arrangement


class _Vertices:
    """Vertex ids by key, merging keys that name the same place."""

    def __init__(self):
        self.xy: list = []
        self.by_key: dict = {}

    def get(self, key, xy) -> int:
        if key not in self.by_key:
            self.by_key[key] = len(self.xy)
            self.xy.append(np.asarray(xy, dtype=float))
        return self.by_key[key]


def _boundary_key(domain, loop: int, seg: int, t: float):
    n = len(domain.loops[loop])
    if t >= 1.0:
        seg, t = (seg + 1) % n, 0.0
    return ("b", loop, seg, round(float(t), 12))


def build_partition(domain, streamlines, element_size: float, cuts=(),
                    dissolve=frozenset(), flat_joints=frozenset(),
                    feature_corners=frozenset(), last_resort=False) -> Partition:
    """Blocks cut out by the streamlines and the ``cuts`` (extra streamlines, see cuts.py),
    less the streamline edges whose origin is in ``dissolve`` (faces merged where a free
    face could not be filled).  ``flat_joints``: (loop, segment) of the loop vertices in a
    feature below the element size (BackgroundMesh.flat_joints): no vertex there, the
    boundary edge runs through (mesh nodes along it at equal arc length).
    ``feature_corners``: (loop, segment, parameter, angle) of such features' corners
    inside a curve (BackgroundMesh.feature_corners): vertices, as a loop's corners are,
    where a face turns by the feature's whole turn (its curve turns a little within the
    reach that measures a face's turns elsewhere).  ``last_resort``: a six-cornered
    face becomes two blocks (subdivide.py) instead of a free face, and a face of up to
    STAR_CORNERS corners or with reflex corners (none next to another, none turning
    back by more than STAR_REFLEX) becomes blocks round a centre; the cut's ends and the
    centres are irregular vertices, so that is the last resort (rounds.blocks_and_mesh)."""
    every = list(streamlines) + list(cuts)
    lines = [np.asarray(s.points, dtype=float) for s in every]
    ends = [(s.start, s.end) for s in every]
    verts = _Vertices()
    tol = 1e-9 * domain.size
    same_place = SAME_PLACE * element_size  # boundary ends this close along a loop are one
    # Split positions along each streamline: (arc-length position, vertex id).
    splits: list[list] = [[] for _ in lines]
    boundary_splits: dict = {li: set() for li in range(len(domain.loops))}
    for li, loop in enumerate(domain.loops):
        for si, curve in enumerate(loop):
            if curve.kind != "circle" and (li, si) not in flat_joints:
                boundary_splits[li].add((si, 0.0))
    bends = []  # (place, turn) of the feature corners
    for li, si, t, angle in sorted(feature_corners):
        boundary_splits[li].add(_boundary_key(domain, li, si, t)[2:])
        bends.append((domain.loops[li][si].point(t), math.pi - angle))
    fixed_places = [place for place, _ in bends] + _loop_corners(domain, flat_joints)
    for k, (pts, (start, end)) in enumerate(zip(lines, ends)):
        # A singular point on the boundary itself (its separatrix there has no length) is
        # that boundary vertex, not a second vertex in the same place.
        if start.kind == "singularity" and end.kind in ("boundary", "corner") \
                and _length(pts) <= 1e-6 * element_size:
            verts.by_key.setdefault(("s", start.index), _end_vertex(
                domain, verts, end, pts[-1], boundary_splits, k, same_place))
    for k, (pts, (start, end)) in enumerate(zip(lines, ends)):
        for where, end_point, pos in ((start, pts[0], 0.0), (end, pts[-1], None)):
            vid = _end_vertex(domain, verts, where, end_point, boundary_splits, k,
                              same_place)
            if vid is None:
                continue  # a T-junction end: resolved once the other line's vertices exist
            splits[k].append((pos if pos is not None else _length(pts), vid))
    # T-junctions: a line ending (or, at a cusp's kite, starting) on another splits the
    # other there.
    for k, (pts, (start, end)) in enumerate(zip(lines, ends)):
        for where, key, point, s_own in ((start, "t0", pts[0], 0.0),
                                         (end, "t", pts[-1], _length(pts))):
            if where.kind == "streamline":
                vid = verts.get((key, k), point)
                splits[where.index].append((where.param * _length(lines[where.index]), vid))
                splits[k].append((s_own, vid))
    # Crossings between streamlines.
    for n, ((i, si), (j, sj), xy) in enumerate(crossings(lines, element_size, tol,
                                                        [end_places(s) for s in every])):
        vid = verts.get(("x", n), xy)  # each crossing is found once
        splits[i].append((si, vid))
        splits[j].append((sj, vid))
    edges = []
    for k, pts in enumerate(lines):
        edges.extend(_split_line(pts, splits[k], k))
    for li in range(len(domain.loops)):
        edges.extend(_boundary_edges(domain, li, sorted(boundary_splits[li]), verts))
    edges = [dataclasses.replace(edge, origin=(edge.streamline, edge.a, edge.b))
             for edge in edges]
    edges = [edge for edge in edges if edge.is_boundary or edge.origin not in dissolve]
    singular = {v for key, v in verts.by_key.items() if key[0] == "s"}
    edges = _one_vertex_per_place(edges, np.array(verts.xy), element_size, singular)
    order = _line_order(lines, element_size)
    edges = _without_dangling(_without_doubles(_without_zero_length(edges, element_size),
                                               element_size, order))
    turns = _vertex_turns(verts.xy, bends, tol)
    # Without the slivers' edges where that leaves no more free faces than with them
    # (where no sliver edge went, the two builds are one).
    corner_counts = tuple(range(3, STAR_CORNERS + 1)) if last_resort else (3, 4, 5)
    thinned = _faces_without_slits(verts.xy, edges, element_size, turns, True, corner_counts,
                                   last_resort, order)
    if thinned[4]:
        kept = _faces_without_slits(verts.xy, edges, element_size, turns, False,
                                    corner_counts, last_resort, order)
        thinned = kept if len(kept[2]) < len(thinned[2]) else thinned
    edges, faces, free, islands, _ = thinned
    vertices, blocks, free = split_odd_faces(verts.xy, edges, faces, free, domain,
                                             unsplit=dissolve, star=last_resort)
    blocks, free = _with_holes(blocks, free, islands, edges, element_size)
    used = {v for edge in edges for v in (edge.a, edge.b)}
    singular = tuple(sorted(singular & used))
    fixed = tuple(sorted(_at_places(vertices, fixed_places, tol) & used))
    return _used_vertices_only(Partition(vertices=np.array(vertices), edges=edges,
                                         blocks=blocks, cuts=list(cuts), singular=singular,
                                         free_faces=free, fixed=fixed))


def _loop_corners(domain, flat_joints) -> list:
    """Places of the loop vertices where the boundary turns (no smooth joint, no joint
    inside a feature read as flat)."""
    out = []
    for li, loop in enumerate(domain.loops):
        for si, curve in enumerate(loop):
            if curve.kind == "circle" or (li, si) in flat_joints:
                continue
            if not is_smooth_join(interior_angle(loop[si - 1], curve)):
                out.append(curve.point(0.0))
    return out


def _at_places(vertices, places, tol) -> set:
    """Ids of the vertices at any of the places (within tol)."""
    if not places or not len(vertices):
        return set()
    xy = np.asarray(vertices, dtype=float)
    out = set()
    for place in places:
        d = np.hypot(*(xy - place).T)
        out.update(int(k) for k in np.nonzero(d <= tol)[0])
    return out


def _faces_without_slits(xy, edges, h, turns, slivers: bool, corner_counts, star,
                         order) -> tuple:
    """(edges, faces, free faces, islands, whether a sliver edge went) once no slit,
    island outline (and, with ``slivers``, sliver edge) is left."""
    thinned = False
    while True:
        faces, free, islands = _faces_to_blocks(np.array(xy), edges, h, turns, corner_counts,
                                                star)
        slits = _slits(free, edges) \
            | {e for island in islands for e, _ in island if not edges[e].is_boundary}
        if slivers:
            thin = _slivers(free, faces, edges, h, order) - slits
            thinned = thinned or bool(thin)
            slits |= thin
        if not slits:
            return edges, faces, free, islands, thinned
        edges = _without_dangling([edge for e, edge in enumerate(edges) if e not in slits])


def _line_order(lines, h) -> list:
    """Each line's place in an order a turned, moved or mirrored copy shares: by length,
    then by the distance of its middle from the lines' centre (rounded).  The lines'
    numbering is the tracing's, which follows the separatrices' numbering round each
    point: a mirror image's runs the other way, and where two lines side by side leave
    one edge between them, the numbering chose which (held-out 0075: another sliver
    dropped, other free faces)."""
    if not lines:
        return []
    middles, lengths = [], []
    for pts in lines:
        cum = cumulative_length(pts)
        lengths.append(float(cum[-1]))
        middles.append(point_at(pts, cum, 0.5 * float(cum[-1])))
    centre = np.mean(middles, axis=0)
    keys = [(round(length / h, 6), round(float(np.hypot(*(m - centre))) / h, 6))
            for length, m in zip(lengths, middles)]
    ranked = sorted(range(len(lines)), key=lambda k: (keys[k], k))
    order = [0] * len(lines)
    for place, k in enumerate(ranked):
        order[k] = place
    return order


def _used_vertices_only(partition: Partition) -> Partition:
    """The partition without the vertices that no edge uses any more (a dropped edge's
    ends), renumbered in order: every vertex becomes a mesh node, and unused nodes are
    no mesh.  (Edge origins keep the first numbering: they name edges across rebuilds.)"""
    used = sorted({v for edge in partition.edges for v in (edge.a, edge.b)})
    if len(used) == len(partition.vertices):
        return partition
    new = {v: k for k, v in enumerate(used)}
    edges = [dataclasses.replace(edge, a=new[edge.a], b=new[edge.b])
             for edge in partition.edges]
    blocks = [dataclasses.replace(block, corners=tuple(new[c] for c in block.corners))
              for block in partition.blocks]
    return dataclasses.replace(partition, vertices=partition.vertices[used], edges=edges,
                               blocks=blocks,
                               singular=tuple(new[v] for v in partition.singular if v in new),
                               fixed=tuple(new[v] for v in partition.fixed if v in new))


def _one_vertex_per_place(edges, xy, h, singular) -> list:
    """Vertices in one place (a trace ending exactly on a singular point, a crossing on a
    T-junction) made one: two vertices there would let a face's walk jump between them
    without an edge, and the face's quads leave a gap.  A boundary vertex, else a singular
    point, is the one kept."""
    if len(xy) < 2:
        return edges
    from scipy.spatial import cKDTree

    pairs = cKDTree(xy).query_pairs(SAME_PLACE * h, output_type="ndarray")
    if not len(pairs):
        return edges
    on_boundary = {v for edge in edges if edge.is_boundary for v in (edge.a, edge.b)}

    def rank(v):
        return (v not in on_boundary, v not in singular, v)

    parent = {}

    def find(v):
        while parent.get(v, v) != v:
            v = parent[v]
        return v

    for a, b in sorted(map(tuple, pairs.tolist())):
        ra, rb = find(a), find(b)
        if ra == rb or (ra in on_boundary and rb in on_boundary):
            continue  # two boundary places are the outline's own business
        keep, drop = sorted((ra, rb), key=rank)
        parent[drop] = keep
    if not parent:
        return edges
    return [dataclasses.replace(edge, a=find(edge.a), b=find(edge.b))
            if edge.a in parent or edge.b in parent else edge for edge in edges]


ZERO_LENGTH = 1e-6  # streamline edges shorter than this (element sizes) join their ends


def _without_zero_length(edges, h) -> list:
    """Streamline edges of no length dropped, their two ends made one vertex (a trace
    stopping on another exactly at a vertex of it): no face walk can order an edge with
    no direction.  A boundary vertex is the one kept."""
    short = [e for e, edge in enumerate(edges)
             if not edge.is_boundary and edge.length <= ZERO_LENGTH * h]
    if not short:
        return edges
    on_boundary = {v for edge in edges if edge.is_boundary for v in (edge.a, edge.b)}
    parent: dict = {}

    def find(v):
        while parent.get(v, v) != v:
            v = parent[v]
        return v

    for e in short:
        a, b = find(edges[e].a), find(edges[e].b)
        if a == b:
            continue
        if b in on_boundary and a not in on_boundary:
            a, b = b, a
        parent[b] = a
    dropped = set(short)
    joined = [dataclasses.replace(edge, a=find(edge.a), b=find(edge.b))
              for e, edge in enumerate(edges) if e not in dropped]
    # A boundary stretch of no length between two places made one is a loop on one
    # vertex now: it would give the vertex four boundary halves, and the face walk there
    # would leave the domain (a whole face lost).
    return [edge for edge in joined if edge.a != edge.b or edge.length > ZERO_LENGTH * h]


DOUBLE_EDGE_GAP = 0.5  # two edges of the same ends closer than this (element sizes) are one


def _without_doubles(edges, h, order) -> list:
    """One edge where two join the same vertices side by side: two separatrices leaving a
    point together and one stopping on the other a step later make a sliver of no width,
    which no face walk can order (their directions at the vertex are the same).  The
    boundary edge, else the earlier streamline's in ``order`` (_line_order), stays."""
    by_ends: dict = {}
    for e, edge in enumerate(edges):
        if edge.a != edge.b:
            by_ends.setdefault(frozenset((edge.a, edge.b)), []).append(e)
    dropped = set()
    for group in by_ends.values():
        group.sort(key=lambda e: (not edges[e].is_boundary,
                                  order[edges[e].streamline] if not edges[e].is_boundary else 0,
                                  e))
        for i, keep in enumerate(group):
            if keep in dropped:
                continue
            for other in group[i + 1:]:
                if other not in dropped and not edges[other].is_boundary \
                        and _side_by_side(edges[keep], edges[other], DOUBLE_EDGE_GAP * h):
                    dropped.add(other)
    return [edge for e, edge in enumerate(edges) if e not in dropped]


def _side_by_side(first: Edge, second: Edge, gap: float) -> bool:
    a = resampled(first.points, 9)
    b = resampled(second.points if second.a == first.a else second.points[::-1], 9)
    return bool(np.hypot(*(a - b).T).max() <= gap)


def _without_dangling(edges) -> list:
    """Streamline edges with an end on nothing else (left by _without_doubles, or a trace
    that stopped in the open) bound no face: dropped, repeatedly (what is left does not
    depend on the order: an edge dropped stays dropped).  One pass with a work list;
    counting every vertex again after each round cost a knurled ring 16 s."""
    edges = list(edges)
    degree: dict = {}
    touching: dict = {}
    for k, edge in enumerate(edges):
        for v in (edge.a, edge.b):
            degree[v] = degree.get(v, 0) + 1
            touching.setdefault(v, []).append(k)
    dropped = [False] * len(edges)
    work = list(degree)
    while work:
        v = work.pop()
        if degree[v] > 1:
            continue
        for k in touching[v]:
            edge = edges[k]
            if dropped[k] or edge.is_boundary or min(degree[edge.a], degree[edge.b]) > 1:
                continue
            dropped[k] = True
            for u in (edge.a, edge.b):
                degree[u] -= 1
                work.append(u)
    return [edge for k, edge in enumerate(edges) if not dropped[k]]


def _with_holes(blocks, free, islands, edges, h) -> tuple:
    """(blocks, free faces) with each remaining island (a hole loop no streamline reaches
    any more) a hole of the smallest face around it; a block around one is no block."""
    if not islands:
        return blocks, free
    faces = [("block", b, tuple(h for side in block.sides for h in side))
             for b, block in enumerate(blocks)]
    faces += [("free", f, face.halves) for f, face in enumerate(free)]
    outlines = [halves_outline(edges, halves) for _, _, halves in faces]
    holes: dict = {}
    for island in islands:
        probe = _left_of(halves_outline(edges, island), 1e-3 * h)
        around = [k for k, o in enumerate(outlines) if inside_polygon(o, probe)]
        if not around:
            raise PartitionError(f"a loop near {fmt(probe)} lies in no face")
        k = min(around, key=lambda k: abs(polygon_area(outlines[k])))
        holes.setdefault(k, []).append(island)
    out_blocks, out_free = [], []
    for k, (kind, index, halves) in enumerate(faces):
        if k not in holes:
            (out_blocks if kind == "block" else out_free).append(
                blocks[index] if kind == "block" else free[index])
            continue
        reason = free[index].reason if kind == "free" else "a block with a hole in it"
        out_free.append(FreeFace(halves, reason, tuple(holes[k])))
    return out_blocks, out_free


def _left_of(outline, offset) -> np.ndarray:
    """A point just left of the middle of the outline's longest segment: inside the
    face the outline bounds, off the outline itself."""
    d = np.diff(outline, axis=0)
    k = int(np.argmax(np.hypot(*d.T)))
    u = d[k] / np.hypot(*d[k])
    return outline[k] + 0.5 * d[k] + offset * np.array([-u[1], u[0]])


def _slits(free, edges) -> set:
    """Streamline edges with a free face on both sides: they separate nothing, and a face
    with a slit is no polygon to fill; without them the face is one.  (So do the edges
    around an island, a group of streamline edges that touches nothing else: they are
    dissolved into the face around them.)"""
    out = set()
    for face in free:
        seen = set()
        for e, _ in face.halves:
            if e in seen and not edges[e].is_boundary:
                out.add(e)
            seen.add(e)
    return out


SLIVER_WIDTH = 0.25  # element sizes: a free face thinner than this on average is a sliver


def _slivers(free, faces, edges, h, order) -> set:
    """The streamline edges of faces thinner than SLIVER_WIDTH that are no four-sided
    block (free, or to be split round a middle vertex): a separatrix that runs along the
    boundary (or along another) a fraction of an element off it leaves a face no quad
    fits in, which its mesh line would only crowd.  Along the boundary, the face's
    streamline edges go (the boundary is the line); between streamlines, those of the
    later streamline in ``order`` (_line_order: the longer); but no edge whose loss
    would leave a line that ends on it hanging (its T-junction gone, the face beyond
    turns back).  (build_partition keeps them all where
    dropping them frees faces: the hexagon's separatrices side by side out of singular
    points a hair apart collapse into one mesh line, zero segment counts, instead.)"""
    walks = [face.halves for face in free]
    walks += [tuple(h for side in face[1] for h in side) for face in faces
              if len(face[1]) != 4 or face[2]]
    hanging = _HangingCheck(edges)
    out = set()
    for halves in walks:
        outline = halves_outline(edges, halves)
        perimeter = float(np.hypot(*np.diff(outline, axis=0).T).sum())
        if 2.0 * abs(polygon_area(outline)) >= SLIVER_WIDTH * h * perimeter:
            continue  # (a strip of width w and length l: area w l, perimeter 2 l)
        inner = {e for e, _ in halves if not edges[e].is_boundary}
        if len(inner) == len(halves):
            last = max(order[edges[e].streamline] for e in inner)
            inner = {e for e in inner if order[edges[e].streamline] == last}
        if not hanging.without(inner):
            out.update(inner)  # (not where it would leave a line that ends on it hanging)
    return out


class _HangingCheck:
    """Whether taking some edges away would leave a streamline edge with an end on
    nothing else (what _without_dangling would drop), found from the degrees of the
    whole arrangement and the taken edges' ends alone: rebuilding the rest and pruning
    it for every thin face cost a knurled ring's partition 24 s."""

    def __init__(self, edges):
        self.edges = edges
        self.degree: dict = {}
        self.touching: dict = {}
        for k, edge in enumerate(edges):
            for v in (edge.a, edge.b):
                self.degree[v] = self.degree.get(v, 0) + 1
                self.touching.setdefault(v, []).append(k)
        self.loose = {k for k, edge in enumerate(edges) if not edge.is_boundary
                      and min(self.degree[edge.a], self.degree[edge.b]) <= 1}

    def without(self, taken) -> bool:
        if self.loose - set(taken):
            return True
        lost: dict = {}
        for k in taken:
            for v in (self.edges[k].a, self.edges[k].b):
                lost[v] = lost.get(v, 0) + 1
        for v, count in lost.items():
            if self.degree[v] - count > 1:
                continue
            if any(k not in taken and not self.edges[k].is_boundary
                   for k in self.touching[v]):
                return True
        return False


def _end_vertex(domain, verts, where, xy, boundary_splits, line_index, tol):
    if where.kind == "singularity":
        return verts.get(("s", where.index), xy)
    if where.kind in ("boundary", "corner"):
        key = _boundary_key(domain, where.loop, where.segment, where.param)
        key = _split_already_there(domain, key, boundary_splits[key[1]], tol) or key
        boundary_splits[key[1]].add((key[2], key[3]))
        return verts.get(key, domain.loops[key[1]][key[2]].point(key[3]))
    if where.kind == "streamline":
        return None
    raise PartitionError(f"streamline {line_index} has an end of unknown kind {where.kind!r}")


def _split_already_there(domain, key, taken, tol):
    """The key of a boundary split already made within ``tol`` along the loop, if any.

    Two traces ending a rounding error apart on the boundary (a separatrix and its
    neighbour meeting a hole's rim at one point) otherwise left a boundary edge of no
    length between two vertices in one place: faces walked it in no direction and a whole
    hole ring came out as one point."""
    _, li, seg, t = key
    loop = domain.loops[li]
    for other_seg, other_t in sorted(taken):
        if _along(loop, (seg, t), (other_seg, other_t)) <= tol:
            return ("b", li, other_seg, other_t)
    return None


def _along(loop, first, second) -> float:
    """Distance along the loop between two (segment, parameter) places on the same or
    neighbouring segments (the shorter way round); inf farther apart."""
    (s1, t1), (s2, t2) = sorted((first, second))
    n = len(loop)
    if s1 == s2:
        gap = abs(t2 - t1) * loop[s1].length
        return min(gap, loop[s1].length - gap) if n == 1 else gap
    if s2 == s1 + 1:
        return (1.0 - t1) * loop[s1].length + t2 * loop[s2].length
    if s1 == 0 and s2 == n - 1:
        return (1.0 - t2) * loop[s2].length + t1 * loop[s1].length
    return math.inf


def _length(pts) -> float:
    return float(np.hypot(*np.diff(pts, axis=0).T).sum())


def _split_line(pts, splits, k):
    """Edges of one streamline between its split positions."""
    cum = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])
    splits = sorted(splits, key=lambda s: s[0])
    edges = []
    for (s_a, v_a), (s_b, v_b) in zip(splits[:-1], splits[1:]):
        if v_a == v_b or s_b - s_a <= 0:
            continue
        inner = pts[(cum > s_a) & (cum < s_b)]
        pa = point_at(pts, cum, s_a)
        pb = point_at(pts, cum, s_b)
        edges.append(Edge(points=np.vstack([pa, inner, pb]), a=v_a, b=v_b, streamline=k))
    return edges


def _boundary_edges(domain, li, positions, verts):
    """Edges along loop li between consecutive split positions, in the loop's direction."""
    loop = domain.loops[li]
    if not positions:
        return []  # an untouched smooth loop: handled by cuts before we get here
    edges = []
    for k, (seg, t) in enumerate(positions):
        nseg, nt = positions[(k + 1) % len(positions)]
        pieces = []
        s, tt = seg, t
        for _ in range(len(loop) + 2):
            if s == nseg and nt > tt:
                pieces.append(BoundaryPiece(li, s, tt, nt))
                break
            pieces.append(BoundaryPiece(li, s, tt, 1.0))
            s, tt = (s + 1) % len(loop), 0.0
            if s == nseg and nt == 0.0:
                break
        pts = [loop[p.segment].point(np.linspace(p.t0, p.t1, _samples(loop[p.segment], p)))
               for p in pieces]
        polyline = np.vstack([pts[0]] + [q[1:] for q in pts[1:]])
        a = verts.get(_boundary_key(domain, li, seg, t), loop[seg].point(t))
        b = verts.get(_boundary_key(domain, li, nseg, nt), loop[nseg].point(nt))
        edges.append(Edge(points=polyline, a=a, b=b, pieces=tuple(pieces),
                          exact_length=pieces_length(domain, pieces)))
    return edges


def _samples(curve, piece) -> int:
    if curve.kind == "line":
        return 2
    return max(3, int(math.ceil(abs(curve.sweep) * abs(piece.t1 - piece.t0) / math.radians(2)))
               + 1)


# ----------------------------------------------------------------------------------------
# Faces and blocks


DIRECTION_PREFIX = 32  # points of a polyline's start measured first (see _direction)


def _direction(points: np.ndarray, reach: float) -> np.ndarray:
    """Unit direction from points[0] toward the point ``reach`` along the polyline.

    Only as much of the polyline is measured as the reach needs (a face walk asks this of
    every edge end, and a trace's polyline holds hundreds of points: 98 000 calls on
    perforated_plate); the prefix's cumulative lengths are the whole one's first entries,
    so the point is the very same."""
    head = points[:DIRECTION_PREFIX]
    cum = cumulative_length(head)
    if not cum[-1] > reach:
        head, cum = points, cumulative_length(points)
    target = point_at(head, cum, min(reach, cum[-1]))
    d = target - points[0]
    n = np.hypot(*d)
    if n == 0:
        d = points[-1] - points[0]
        n = np.hypot(*d)
    if n == 0:
        raise PartitionError(f"a partition edge has zero length at {fmt(points[0])}")
    return d / n


SECTOR_MARGIN = 1e-6  # radians inside the domain's sector a clamped direction is put


def _into_the_domain(items, half, edges) -> None:
    """At a boundary vertex, streamline directions that point out of the domain (a trace
    leaving tangentially along a convex curve, measured by a chord) are put just inside
    the sector between the two boundary edges: a face walk must never leak outside."""
    boundary = [(angle, hid) for angle, hid in items if edges[half[hid][0]].is_boundary]
    if len(boundary) != 2:
        return
    (a0, h0), (a1, h1) = boundary
    out_angle, in_angle = (a0, a1) if half[h0][1] else (a1, a0)  # forward: leaves along loop
    if half[h0][1] == half[h1][1]:
        return
    width = (in_angle - out_angle) % (2 * math.pi)
    for k, (angle, hid) in enumerate(items):
        if edges[half[hid][0]].is_boundary:
            continue
        offset = (angle - out_angle) % (2 * math.pi)
        if offset <= width:
            continue
        past = offset - width  # beyond the incoming edge
        before = 2 * math.pi - offset  # short of the outgoing edge
        target = in_angle - SECTOR_MARGIN if past < before else out_angle + SECTOR_MARGIN
        items[k] = (math.atan2(math.sin(target), math.cos(target)), hid)


SAME_DIRECTION = 1e-7  # radians: two edges leaving a vertex this close run together
FARTHER = (1.0, 2.0, 4.0)  # reaches (element sizes) that tell such edges apart


def _around(items, half, edges, h) -> list:
    """The (angle, half) items of a vertex in counter-clockwise order.  Edges leaving in
    one direction (two clamped into the domain's sector alike, a trace starting along
    another) are ordered by where they head farther on, not by their numbers, which a
    mirrored or turned copy of the part does not share."""
    items = sorted(items)
    if len(items) < 2:
        return items

    def farther(hid, reach):
        e, forward = half[hid]
        pts = edges[e].points if forward else edges[e].points[::-1]
        d = _direction(pts, min(reach * h, edges[e].length))
        return math.atan2(d[1], d[0])

    out, k = [], 0
    while k < len(items):
        run = [items[k]]
        while k + len(run) < len(items) and \
                items[k + len(run)][0] - run[-1][0] <= SAME_DIRECTION:
            run.append(items[k + len(run)])
        if len(run) > 1:
            run.sort(key=lambda item, base=run[0][0]: tuple(
                round(_wrapped(farther(item[1], r) - base), 9) for r in FARTHER))
        out.extend(run)
        k += len(run)
    return out


def _wrapped(angle: float) -> float:
    """The angle in (-pi, pi]."""
    return math.atan2(math.sin(angle), math.cos(angle))


def _vertex_turns(xy, bends, tol) -> dict:
    """Vertex id -> turn of the feature corners among the vertices."""
    out = {}
    for place, turn in bends:
        d = np.hypot(*(np.asarray(xy) - place).T)
        k = int(np.argmin(d))
        if d[k] <= tol:
            out[k] = turn
    return out


def _faces_to_blocks(vertices, edges, h, vertex_turns=None, corner_counts=(3, 4, 5),
                     star=False):
    """(faces, free faces, islands): a face is (corner vertex ids, sides, the indices in
    its corners of reflex ones); ``star``: see build_partition's ``last_resort``."""
    reach = 0.5 * h
    half = []  # (edge id, forward)
    out_dirs: dict = {}
    for e, edge in enumerate(edges):
        reach_e = min(reach, edge.length / 3)
        for forward in (True, False):
            pts = edge.points if forward else edge.points[::-1]
            v = edge.a if forward else edge.b
            d = _direction(pts, reach_e)
            out_dirs.setdefault(v, []).append((math.atan2(d[1], d[0]), len(half)))
            half.append((e, forward))
    order = {}
    for v, items in out_dirs.items():
        _into_the_domain(items, half, edges)
        items = _around(items, half, edges, h)
        out_dirs[v] = items
        for k, (_, hid) in enumerate(items):
            order[hid] = (v, k)
    twin = {}
    for hid, (_, forward) in enumerate(half):
        twin[hid] = hid + 1 if forward else hid - 1  # halves come in pairs

    def head(hid):
        e, forward = half[hid]
        return edges[e].b if forward else edges[e].a

    def next_half(hid):
        t = twin[hid]
        v, k = order[t]
        items = out_dirs[v]
        return items[(k - 1) % len(items)][1]

    seen = set()
    blocks, free, islands = [], [], []
    for start in range(len(half)):
        if start in seen:
            continue
        cycle = []
        hid = start
        while hid not in seen:
            seen.add(hid)
            cycle.append(hid)
            hid = next_half(hid)
            if len(cycle) > len(half):
                raise PartitionError("the arrangement of streamlines is not planar")
        if any(edges[half[c][0]].is_boundary and not half[c][1] for c in cycle):
            continue  # outside the domain (the outer face, or inside a hole)
        if signed_area(edges, [half[c] for c in cycle]) <= 0:
            islands.append(tuple(half[c] for c in cycle))  # the outside of an island
            continue
        try:
            blocks.append(_block_of(cycle, half, edges, vertices, h, head, vertex_turns or {},
                                    corner_counts, star))
        except PartitionError as exc:
            places = [vertices[edges[half[c][0]].a if half[c][1] else edges[half[c][0]].b]
                      for c in cycle]
            for lobe in _lobes([half[c] for c in cycle], places, h):
                if signed_area(edges, lobe) > 0:
                    free.append(FreeFace(lobe, str(exc)))
                else:
                    islands.append(lobe)
    return blocks, free, islands


SAME_PLACE = 1e-6  # vertices closer than this (element sizes) are one place of a face


def _lobes(halves, places, h) -> list:
    """A face's walk split where it passes one place twice (a pinch) into simple loops:
    each is a polygon of its own, where the whole walk is none."""
    tol = SAME_PLACE * h
    place_id = []
    for k, p in enumerate(places):
        same = [place_id[j] for j in range(k) if np.hypot(*(places[j] - p)) <= tol]
        place_id.append(same[0] if same else k)
    lobes, stack = [], []  # stack: (place, half) of the walk not yet in a lobe
    for place, h_e in zip(place_id, halves):
        at = next((i for i, (q, _) in enumerate(stack) if q == place), None)
        if at is not None:
            lobes.append(tuple(x for _, x in stack[at:]))
            del stack[at:]
        stack.append((place, h_e))
    if stack:
        lobes.append(tuple(x for _, x in stack))
    return lobes


def _with_more_corners(turns, corner_at, lengths):
    """A face of two or three corners whose sides bend somewhere by PROMOTED_TURN or more
    at enough places gets its missing corners at the sharpest bends: one block, where
    the face is no block at all.  Three corners: a chamfer's end at a spike's tip, a
    polyline's kink, where the quads then meet at the boundary's own angle as gmsh's do,
    instead of three blocks squeezed into the face round an extra irregular vertex.  Two:
    a lens (a separatrix hugging the boundary from one singular point to the next, past a
    flat between two scallops).  Where bends tie for the last place taken (a C-shaped
    clamp's eight 135° chamfer corners, its two tips the face's corners), the choice
    among them whose block has its opposite sides nearest in length is taken: the
    clamp's ends are the flats from each tip to the next chamfer, not the top's
    chamfers, whose block would pair a side of 25 with one of 80.  ``lengths``: of each
    half-edge of the face (the one ending at position k).  A tie in that too leaves the
    face as it is, so that no pose decides it."""
    missing = 4 - len(corner_at)
    rest = np.setdiff1d(np.arange(len(turns)), corner_at)
    rest = rest[turns[rest] >= PROMOTED_TURN]
    if len(rest) < missing:
        return corner_at
    ranked = rest[np.argsort(-turns[rest], kind="stable")]
    last = turns[ranked[missing - 1]]
    sure = [int(k) for k in ranked if turns[k] - last > TURN_TIE]
    tied = [int(k) for k in ranked if abs(turns[k] - last) <= TURN_TIE]
    choices = {tuple(sorted(sure + list(pick)))
               for pick in itertools.combinations(tied, missing - len(sure))}
    scored = sorted((_imbalance(np.sort(np.concatenate([corner_at, choice])), lengths),
                     choice) for choice in choices)
    if len(scored) > 1 and scored[1][0] - scored[0][0] <= BALANCE_TIE:
        return corner_at
    return np.sort(np.concatenate([corner_at, scored[0][1]])).astype(int)


BALANCE_TIE = 1e-6  # imbalances this close are a tie


def _imbalance(corner_at, lengths) -> float:
    """How far a four-cornered face's opposite sides are from equal lengths: the sum over
    both pairs of |a - b| / (a + b), rounded so that round-off cannot order two pairs.
    Corner k sits at the head of half-edge k; side s runs from corner s to corner s + 1."""
    cum = np.concatenate([[0.0], np.cumsum(lengths)])
    total = cum[-1]
    sides = [(cum[corner_at[(s + 1) % 4] + 1] - cum[corner_at[s] + 1]) % total
             for s in range(4)]
    return round(sum(abs(sides[s] - sides[s + 2]) / (sides[s] + sides[s + 2])
                     for s in range(2)), 9)


def corners_instead_of_4(n: int) -> str:
    """How a free face's reason names a face with n corners (rounds.blocks_and_mesh
    looks for six)."""
    return f"has {n} corners instead of 4"


def _block_of(cycle, half, edges, vertices, h, head, vertex_turns, corner_counts, star):
    reach = 0.5 * h
    turns = []
    for k, hid in enumerate(cycle):
        nxt = cycle[(k + 1) % len(cycle)]
        e_in, f_in = half[hid]
        e_out, f_out = half[nxt]
        pin = edges[e_in].points if f_in else edges[e_in].points[::-1]
        pout = edges[e_out].points if f_out else edges[e_out].points[::-1]
        d_in = -_direction(pin[::-1], min(reach, edges[e_in].length / 3))
        d_out = _direction(pout, min(reach, edges[e_out].length / 3))
        turn = math.atan2(d_in[0] * d_out[1] - d_in[1] * d_out[0], float(d_in @ d_out))
        if math.pi - abs(turn) <= TURN_TIE:
            turn = _turn_back(pin, pout, d_in)
        if head(hid) in vertex_turns and edges[e_in].is_boundary and edges[e_out].is_boundary:
            turn = vertex_turns[head(hid)]  # a feature corner, the boundary both sides
        turns.append(turn)
    turns = np.array(turns)
    # A turn at the very threshold (a 45° chamfer met by a field line along one of its
    # edges) is exactly CORNER_TURN, decided alike in every pose: neither a corner nor a
    # turn back, not whichever side round-off put it on.
    at_threshold = np.abs(np.abs(turns) - CORNER_TURN) <= TURN_TIE
    turns = np.where(at_threshold, np.sign(turns) * CORNER_TURN, turns)
    outline = halves_outline(edges, [half[c] for c in cycle])
    tips = np.array([vertices[head(c)] for c in cycle])
    reflex = turns < -CORNER_TURN
    corner_at = np.nonzero(turns > CORNER_TURN)[0]  # corner at the head of cycle[k]
    if reflex.any():
        k = int(np.argmin(turns))
        if not (star and _star_face(turns, corner_at, [head(c) for c in cycle])):
            raise PartitionError(f"a block turns back by {-math.degrees(turns[k]):.0f}° near "
                                 f"{fmt(vertices[head(cycle[k])])}: not a four-sided block")
        corner_at = np.nonzero(reflex | (turns > CORNER_TURN))[0]
    elif len(corner_at) in (2, 3):
        lengths = np.array([edges[half[c][0]].length for c in cycle])
        corner_at = _with_more_corners(turns, corner_at, lengths)
    if star and len(corner_at) >= 6 and len(set(head(c) for c in cycle)) < len(cycle):
        raise PartitionError("a block touches itself: not a four-sided block")
    if not reflex.any() and len(corner_at) not in corner_counts:
        centre = np.mean([vertices[head(c)] for c in cycle], axis=0)
        raise PartitionError(f"a block near {fmt(centre)} {corners_instead_of_4(len(corner_at))}",
                             outline, tips[corner_at])
    n_sides = len(corner_at)
    sides = []
    corners = []
    for s in range(n_sides):
        first = (corner_at[s] + 1) % len(cycle)
        last = corner_at[(s + 1) % n_sides]
        idx = []
        k = first
        while True:
            idx.append(k)
            if k == last:
                break
            k = (k + 1) % len(cycle)
        sides.append([half[cycle[i]] for i in idx])
        corners.append(head(cycle[corner_at[s]]))
    return corners, sides, tuple(int(j) for j in np.nonzero(reflex[corner_at])[0])


def _turn_back(arriving, leaving, d_in) -> float:
    """The turn, pi or -pi, where a face's outline leaves a vertex the way it came (a
    line that runs on along a boundary's flat and then parts from it): pi (a corner of
    no angle) where the leaving edge lies on the face's side, the left, of the arriving
    one, as their far ends show; -pi (turns back) otherwise.  Round-off gave the sign:
    held-out sensor-assembly f89 had one of its two such faces a block and the other
    not, and its mirror image both free."""
    gap = np.asarray(leaving[-1], float) - np.asarray(arriving[0], float)
    side = d_in[0] * gap[1] - d_in[1] * gap[0]
    return math.pi if side > 0.0 else -math.pi


def _star_face(turns, corner_at, places) -> bool:
    """Whether a face with reflex corners can be split round a centre: from 3 to
    STAR_CORNERS other corners, no reflex corner turning back by more than STAR_REFLEX
    or next to another, and no place passed twice (a pinch)."""
    reflex = turns < -CORNER_TURN
    if turns.min() < -STAR_REFLEX or not 3 <= len(corner_at) <= STAR_CORNERS:
        return False
    kinds = reflex[np.nonzero(reflex | (turns > CORNER_TURN))[0]]
    if (kinds & np.roll(kinds, -1)).any():
        return False
    return len(set(places)) == len(places)
