"""The block-structured quad mesh: each partition edge discretised once, each block filled
by transfinite (Coons) interpolation, then smoothed without ever inverting an element.

Edges are shared by the blocks on both sides, so the mesh is conforming by construction;
nodes on boundary edges are placed on the exact curves (arc-length spacing) and move only
along them, where that raises the worst quads (improve.py).  Free faces (no blocks, see
partition.py) get gmsh's unstructured quads on the side nodes their neighbours use
(free_faces.py); their quads belong to block -1.  Interior nodes, including those on
streamline edges and at singular points, are smoothed (Laplacian) under a guard that undoes
any move that would make a quad's scaled Jacobian drop below the smaller of its current
value and SMOOTH_FLOOR; then the worst quads get max-min moves (improve.py).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

import numpy as np

from ..input.corners import interior_angle
from ..input.features import is_smooth_join
from ..input.pose import canonical_pose
from ..layout.collapse import conflicts, merges, node_layout, side_nodes
from ..layout.partition_types import FreeFaceError, Partition, PartitionError
from .edge_graph import edge_graph, neighbour_means
from .free_faces import free_face_fills
from .improve import BoundarySlide, improve_worst, polish_worst, sj_batch, strip_slides
from .orientation import signed_areas
from .straighten import straightened

SMOOTH_ITERATIONS = 40
SMOOTH_FLOOR = 0.3


@dataclass(frozen=True)
class QuadMesh:
    nodes: np.ndarray  # (N, 2)
    quads: np.ndarray  # (Q, 4) counter-clockwise
    block_of_quad: np.ndarray  # (Q,)
    boundary: np.ndarray  # (N,) bool: node lies on the domain boundary
    edge_nodes: tuple  # per partition edge: node ids from its vertex a to vertex b
    free_face_of_quad: np.ndarray = None  # (Q,) the partition's free face a quad fills, or -1


def _boundary_edge_points(domain, edge, n: int) -> tuple:
    """n + 1 points at equal arc length along the exact curve stretches of the edge, with
    the stretch (piece index) and curve parameter of each."""
    curves = [domain.loops[p.loop][p.segment] for p in edge.pieces]
    lengths = np.array([c.length * abs(p.t1 - p.t0) for c, p in zip(curves, edge.pieces)])
    cum = np.concatenate([[0.0], np.cumsum(lengths)])
    s = np.linspace(0.0, cum[-1], n + 1)
    out = np.empty((n + 1, 2))
    where = []
    for k, sk in enumerate(s):
        i = int(np.clip(np.searchsorted(cum, sk, side="right") - 1, 0, len(curves) - 1))
        p = edge.pieces[i]
        f = (sk - cum[i]) / lengths[i] if lengths[i] > 0 else 0.0
        t = p.t0 + min(max(f, 0.0), 1.0) * (p.t1 - p.t0)
        if k == n:
            t = p.t1 if i == len(curves) - 1 else t
        out[k] = curves[i].point(float(t))
        where.append((i, float(t)))
    return out, where


def _slides(domain, partition, layout, ids, where) -> dict:
    """The boundary nodes that may slide along the boundary (see improve.py): every inner
    node of a boundary edge, bounded by its neighbours on the same stretch.  A stretch
    runs over the curves the edge passes through where they join smoothly (a tangent
    joint, or one turning under SMOOTH_TURN): a one-element strip bent round a fillet
    needs its nodes to cross from the fillet to the line beside it, and the node count on
    the inner and the outer fillet rarely matches."""
    slides = {}
    for e, (edge, spots) in enumerate(zip(partition.edges, where)):
        if spots is None:
            continue
        nodes = ids[layout.edge_nodes[e]]
        chain = _EdgeChain(domain, edge)
        along = [chain.arc_length(i, t) for i, t in spots]
        stretch = [chain.stretch_of[i] for i, _ in spots]
        for k in range(1, len(spots) - 1):
            lo, hi = chain.stretch_bounds(stretch[k])
            same_before = stretch[k - 1] == stretch[k]
            same_after = stretch[k + 1] == stretch[k]
            slides[int(nodes[k])] = BoundarySlide(
                curve=chain, t=along[k],
                before=int(nodes[k - 1]) if same_before and k > 1 else None,
                after=int(nodes[k + 1]) if same_after and k < len(spots) - 2 else None,
                t_before=along[k - 1] if same_before else lo,
                t_after=along[k + 1] if same_after else hi)
    return slides


class _EdgeChain:
    """A boundary edge's exact curve stretches as one curve of its arc length, split
    into stretches at the joints that are no smooth joins."""

    def __init__(self, domain, edge):
        self.curves = [domain.loops[p.loop][p.segment] for p in edge.pieces]
        self.pieces = edge.pieces
        lengths = [c.length * abs(p.t1 - p.t0) for c, p in zip(self.curves, self.pieces)]
        self.start = np.concatenate([[0.0], np.cumsum(lengths)])
        self.stretch_of = [0]
        for i in range(1, len(self.curves)):
            smooth = is_smooth_join(interior_angle(self.curves[i - 1], self.curves[i]))
            self.stretch_of.append(self.stretch_of[-1] + (not smooth))

    def arc_length(self, i: int, t: float) -> float:
        p = self.pieces[i]
        span = p.t1 - p.t0
        f = (t - p.t0) / span if span else 0.0
        return float(self.start[i] + f * (self.start[i + 1] - self.start[i]))

    def stretch_bounds(self, stretch: int) -> tuple:
        mine = [i for i, k in enumerate(self.stretch_of) if k == stretch]
        return float(self.start[mine[0]]), float(self.start[mine[-1] + 1])

    def point(self, s):
        """The point at arc length ``s``, or the points at an array of them (as the
        curves take their parameters), each curve's in one call: the boundary slides ask
        for six at a time, thousands of times on a bent strip (held-out 0086)."""
        if np.ndim(s) == 0:
            return self.point(np.array([s], dtype=float))[0]
        s = np.asarray(s, dtype=float)
        i = np.minimum(np.maximum(np.searchsorted(self.start, s, side="right") - 1, 0),
                       len(self.curves) - 1)
        length = self.start[i + 1] - self.start[i]
        f = np.minimum(np.maximum((s - self.start[i]) / np.where(length > 0, length, 1.0),
                                  0.0), 1.0)
        f[length <= 0] = 0.0
        out = np.empty((len(s), 2))
        for k in set(i.tolist()):
            mine = i == k
            p = self.pieces[k]
            out[mine] = self.curves[k].point(p.t0 + f[mine] * (p.t1 - p.t0))
        return out


def _polyline_points(points: np.ndarray, n: int) -> np.ndarray:
    seg = np.hypot(*np.diff(points, axis=0).T)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    s = np.linspace(0.0, cum[-1], n + 1)
    k = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(seg) - 1)
    f = np.clip((s - cum[k]) / np.maximum(seg[k], 1e-300), 0.0, 1.0)
    return points[k] + f[:, None] * (points[k + 1] - points[k])


def build_quad_mesh(domain, partition: Partition, counts, smoothing: bool = True,
                    finer_fills: bool = False) -> QuadMesh:
    """The quad mesh of a partition and its segment counts; FreeFaceError where a free
    face cannot be filled.  ``finer_fills``: such a face is tried again with its boundary
    segments split (_finer_free_face) before it counts as unfillable."""
    layout = node_layout(partition, counts)
    found = merges(partition, layout, counts)
    if conflicts(layout, found):
        raise PartitionError("the segment counts merge two boundary nodes or singular points")
    raw = np.zeros((layout.n_nodes, 2))
    raw[: len(partition.vertices)] = partition.vertices
    where = [None] * len(partition.edges)
    for e, edge in enumerate(partition.edges):
        n = int(counts[e])
        if n == 0:
            continue
        if edge.is_boundary:
            pts, where[e] = _boundary_edge_points(domain, edge, n)
        else:
            pts = _polyline_points(edge.points, n)
        raw[layout.edge_nodes[e][1:-1]] = pts[1:-1]
    # A merged place: the boundary node if it holds one (boundary nodes stay on the boundary), else
    # the mean of what was merged (two side-by-side separatrices meet half-way).
    root = found.parent
    used = np.unique(root)
    compact = np.full(layout.n_nodes, -1, dtype=np.int64)
    compact[used] = np.arange(len(used))
    ids = compact[root]
    total = np.zeros((len(used), 2))
    np.add.at(total, ids, raw)
    positions = list(total / np.bincount(ids, minlength=len(used))[:, None])
    boundary_ids = set(ids[layout.boundary].tolist())
    for x in np.nonzero(layout.boundary)[0]:
        positions[ids[x]] = raw[x]
    _place_slid_nodes(domain, partition, counts, layout, ids, raw, positions)
    quads, owner = [], []
    for b, block in enumerate(partition.blocks):
        if b in found.collapsed:
            continue
        sides = [ids[side_nodes(layout, counts, side)] for side in block.sides]
        n, m = len(sides[0]) - 1, len(sides[1]) - 1
        if len(sides[2]) - 1 != n or len(sides[3]) - 1 != m:
            raise PartitionError(f"block {b}: opposite sides have {n}/{len(sides[2]) - 1} and "
                                 f"{m}/{len(sides[3]) - 1} segments")
        grid = np.full((n + 1, m + 1), -1, dtype=np.int64)
        grid[:, 0] = sides[0]
        grid[n, :] = sides[1]
        grid[:, m] = sides[2][::-1]
        grid[0, :] = sides[3][::-1]
        xy = np.array(positions)
        interior = _coons(xy[grid[:, 0]], xy[grid[:, m]], xy[grid[0, :]], xy[grid[n, :]])
        for i in range(1, n):
            for j in range(1, m):
                grid[i, j] = len(positions)
                positions.append(interior[i, j])
        q = np.stack([grid[:-1, :-1], grid[1:, :-1], grid[1:, 1:], grid[:-1, 1:]], axis=-1)
        quads.append(q.reshape(-1, 4))
        owner.append(np.full(n * m, b))
    free_owner = [np.full(len(q), -1) for q in quads]
    if partition.free_faces:
        pose = canonical_pose(domain)
        failed, origins = [], set()  # every face that cannot be filled, so one rebuild
        for f, face in enumerate(partition.free_faces):  # can merge them all
            try:
                try:
                    q = _free_face(layout, ids, positions, face, pose)
                except PartitionError:
                    if not finer_fills:
                        raise
                    q = _finer_free_face(domain, partition, layout, ids, positions, face,
                                         pose, where, boundary_ids)
            except PartitionError as exc:
                failed.append(str(exc))
                origins |= {partition.edges[e].origin for ring in face.rings for e, _ in ring
                            if not partition.edges[e].is_boundary}
                continue
            quads.append(q)
            owner.append(np.full(len(q), -1))
            free_owner.append(np.full(len(q), f))
        if failed:
            raise FreeFaceError(failed[0], origins)
    nodes = np.array(positions, dtype=float)
    quads = np.concatenate(quads) if quads else np.zeros((0, 4), dtype=np.int64)
    owner = np.concatenate(owner) if owner else np.zeros(0, dtype=np.int64)
    ordered = np.sort(quads, axis=1)
    squashed = (ordered[:, 1:] == ordered[:, :-1]).any(axis=1)
    if squashed.any():
        raise SquashedBlocks("the segment counts squash a block into a quad with a repeated "
                             "corner", sorted({int(b) for b in owner[squashed] if b >= 0}))
    boundary = np.zeros(len(nodes), dtype=bool)
    boundary[list(boundary_ids)] = True
    quads = _turned_by_block(nodes, quads, owner)
    if smoothing:
        nodes = improve_worst(smooth(nodes, quads, boundary), quads, boundary)
        if sj_batch(nodes[quads]).min() > 0:
            # Boundary nodes slide only in a mesh with no inverted quad: whether a fold
            # is left (and its blocks freed) is decided as before, alike in every pose,
            # not by how far a slide happened to rescue it.
            slides = _slides(domain, partition, layout, ids, where)
            nodes = improve_worst(nodes, quads, boundary, slides=slides)
            nodes = strip_slides(nodes, quads, boundary, slides)
            straight = straightened(nodes, quads, boundary, slides, owner)
            moved = straight is not nodes
            nodes = polish_worst(nodes, quads, boundary)
            if moved:
                # The polish is local: from the straightened mesh it may end lower than
                # from the one before (grabcad_misc_part1 at diameter/100: 0.66, 0.70).
                straight = polish_worst(straight, quads, boundary)
                if _worst(straight, quads) > _worst(nodes, quads):
                    nodes = straight
    edge_nodes = tuple(ids[e_nodes] if int(counts[e]) else ids[e_nodes[[0, -1]]]
                       for e, e_nodes in enumerate(layout.edge_nodes))
    free_owner = np.concatenate(free_owner) if free_owner else np.zeros(0, dtype=np.int64)
    return QuadMesh(nodes=nodes, quads=quads, block_of_quad=owner, boundary=boundary,
                    edge_nodes=edge_nodes, free_face_of_quad=free_owner)


def _worst(nodes, quads) -> float:
    return round(float(sj_batch(nodes[quads]).min()), 9)


def _turned_by_block(nodes, quads, owner) -> np.ndarray:
    """Quads counter-clockwise, each block's all one way: the way most of its area runs.
    A quad its map lays inverted then stays inverted, for smoothing to mend; turned on
    its own it looked fine to every check of a quad while it folded over its neighbours,
    and smoothing made it finer still (a flange of Open CASCADE's samples at its default
    size: thin strips along its sides, where a hole's arc bulged the middle row of the
    map out of the strip, folded and given up: 64 % of it in blocks, worst 0.06; all in
    blocks and 0.86 since).  A free face's quads are turned one by one (gmsh's)."""
    area = signed_areas(nodes, quads)
    mapped = owner >= 0
    clockwise = area < 0
    if mapped.any():
        clockwise[mapped] = np.bincount(owner[mapped], weights=area[mapped])[owner[mapped]] < 0
    return np.where(clockwise[:, None], quads[:, ::-1], quads)


def _place_slid_nodes(domain, partition, counts, layout, ids, raw, positions) -> None:
    """Boundary nodes merged along boundary arcs with no segments (collapse.py): on the
    corner among them if there is one, else half-way along the run of those arcs, by arc
    length (so that the place does not hang on which end came first, nor on which of two
    arcs of one length round-off makes the longer: nist_ctc_01's face 116 has such pairs,
    and a moved copy's node sat on the other arc's middle, a fifth of an element away,
    where a free face beside it could no longer be filled)."""
    zero = [e for e, edge in enumerate(partition.edges)
            if edge.is_boundary and int(counts[e]) == 0]
    if not zero:
        return
    placed = set()
    for x in np.nonzero(layout.fixed & layout.boundary)[0]:
        positions[ids[x]] = raw[x]
        placed.add(int(ids[x]))
    runs = {}
    for e in zero:
        runs.setdefault(int(ids[partition.edges[e].a]), []).append(e)
    for node, run in runs.items():
        if node not in placed:
            positions[node] = _middle_of_run(domain, partition, run)


def _middle_of_run(domain, partition, run) -> np.ndarray:
    """The point half-way along boundary edges that join end to end (in any order and
    direction); for edges that do not make one open path, the middle of the longest."""
    ends = Counter(v for e in run for v in (partition.edges[e].a, partition.edges[e].b))
    tips = sorted(v for v, n in ends.items() if n == 1)
    chains = {e: _EdgeChain(domain, partition.edges[e]) for e in run}
    if len(tips) != 2 or len(ends) != len(run) + 1:
        longest = max(run, key=lambda e: (round(float(chains[e].start[-1]), 12), -e))
        return chains[longest].point(0.5 * float(chains[longest].start[-1]))
    walk, at, left = [], tips[0], set(run)
    while left:
        e = next(e for e in sorted(left) if at in (partition.edges[e].a, partition.edges[e].b))
        forward = partition.edges[e].a == at
        walk.append((e, forward))
        at = partition.edges[e].b if forward else partition.edges[e].a
        left.remove(e)
    half = 0.5 * sum(float(chains[e].start[-1]) for e, _ in walk)
    for k, (e, forward) in enumerate(walk):
        length = float(chains[e].start[-1])
        if half <= length or k == len(walk) - 1:
            half = min(half, length)
            return chains[e].point(half if forward else length - half)
        half -= length


class SquashedBlocks(PartitionError):
    """Blocks (indices) that the segment counts squash: freeing them may help."""

    def __init__(self, message, blocks):
        super().__init__(message)
        self.blocks = blocks


def _free_face(layout, ids, positions, face, pose) -> np.ndarray:
    """Quads of one free face (global node ids); its interior points join positions."""
    return _filled(_face_rings(layout, ids, face), positions, face, pose)


def _face_rings(layout, ids, face, between=None) -> list:
    """Node ids round each ring of a free face, its edges' nodes in walking order;
    ``between(e, forward)``: per segment of edge e, the ids of extra nodes inside it
    (None: none)."""
    rings = []
    for ring_halves in face.rings:
        ring = []
        for e, forward in ring_halves:
            part = layout.edge_nodes[e] if forward else layout.edge_nodes[e][::-1]
            nodes = [int(i) for i in ids[part]]
            extra = between(e, forward) if between is not None else None
            for k in range(len(nodes) - 1):
                ring.append(nodes[k])
                if extra is not None:
                    ring.extend(extra[k])
        rings.append(np.array(ring, dtype=np.int64))
    return rings


FINER_SIDES = (3, 9)  # a free face's boundary segments split in this many, in turn


def _finer_free_face(domain, partition, layout, ids, positions, face, pose, where,
                     boundary_ids) -> np.ndarray:
    """_free_face with the segments of its boundary edges split in FINER_SIDES parts on
    the exact curves, where the side nodes the counts gave cannot be filled: a boundary
    edge belongs to this face alone, so its extra nodes keep the mesh conforming, and
    gmsh then follows detail far below the element size (an engraved logo's strokes,
    whose chords crossed: the rebuilds dissolved every line round the logo, and gmsh's
    quads stood in for the whole face).  Splits in an odd number of parts keep every
    ring's node count even."""
    for parts in FINER_SIDES:
        before = len(positions)
        added = []
        rings = _face_rings(layout, ids, face,
                            _splitter(domain, partition, where, parts, positions, added))
        if not added:
            break
        try:
            quads = _filled(rings, positions, face, pose)
        except PartitionError:
            del positions[before:]
            continue
        boundary_ids.update(added)
        return quads
    raise PartitionError(f"a free face ({face.reason}) gets inverted quads on its "
                         "curved sides")


def _splitter(domain, partition, where, parts: int, positions: list, added: list):
    """_face_rings' ``between`` for _finer_free_face: each boundary segment's split
    points join ``positions`` (their ids also ``added``)."""
    def between(e, forward):
        extra = _split_points(domain, partition.edges[e], where[e], parts, forward)
        if extra is None:
            return None
        ids_of = []
        for points in extra:
            ids_of.append(list(range(len(positions), len(positions) + len(points))))
            positions.extend(points)
            added.extend(ids_of[-1])
        return ids_of

    return between


def _split_points(domain, edge, spots, parts: int, forward: bool):
    """Per segment of a boundary edge (in the walking direction), the parts - 1 points
    that split it evenly along the exact curve; None for a streamline edge."""
    if spots is None:
        return None
    chain = _EdgeChain(domain, edge)
    along = np.array([chain.arc_length(i, t) for i, t in spots])
    if not forward:
        along = along[::-1]
    steps = np.arange(1, parts) / parts
    return [chain.point(a + steps * (b - a)) for a, b in zip(along[:-1], along[1:])]


def _filled(rings, positions, face, pose) -> np.ndarray:
    """gmsh's quads for the face bounded by ``rings`` (node ids); see _free_face."""
    every = np.concatenate(rings)
    if len(np.unique(every)) != len(every):
        raise PartitionError(f"a free face ({face.reason}) touches itself: no polygon to fill")
    xy = np.array(positions)
    # gmsh places its nodes for the straightened outline; where the neighbours' side
    # nodes bend it so far that no moving of them unfolds the quads, another of gmsh's
    # algorithms often lays them out so that it does.
    for interior, local in free_face_fills([xy[r] for r in rings], pose):
        points = np.vstack([xy[every], interior])
        if signed_areas(points, local).sum() < 0:
            local = local[:, ::-1]  # one orientation for all: a folded quad stays negative
        if sj_batch(points[local]).min() <= FLAT_FILL:
            points = _untangled(points, local, len(every))
        if sj_batch(points[local]).min() > FLAT_FILL:
            break
    else:
        raise PartitionError(f"a free face ({face.reason}) gets inverted quads on its "
                             "curved sides")
    interior = points[len(every):]
    first = len(positions)
    positions.extend(interior)
    return np.where(local < len(every), every[np.minimum(local, len(every) - 1)],
                    local - len(every) + first)


UNTANGLE_PASSES = 30
UNTANGLE_RINGS = 3
# A fill's quad no better than this is folded: a flat one (three nodes on one straight
# side) reads 0 or +-1e-17 by the pose, and round-off must not decide whether the fill
# is kept (held-out 0075: another fill, other lines dissolved, at 37°).
FLAT_FILL = 1e-9


def _untangled(points, local, n_ring) -> np.ndarray:
    """gmsh's quads for a thin or strongly curved free face, with its interior nodes moved
    (max-min compass search, the side nodes fixed) until no quad is inverted if that can
    be had: gmsh places them for the straightened outline, the neighbours' side nodes
    bend it.  ``local``: all counter-clockwise, so an inverted quad reads negative."""
    fixed = np.zeros(len(points), dtype=bool)
    fixed[:n_ring] = True
    if fixed.all():
        return points
    # Plain Laplacian first (a fold where a curved side bulges into gmsh's centre nodes
    # needs them pulled towards their neighbours), kept only where it does better.
    relaxed = _laplacian(points, local, fixed, UNTANGLE_PASSES)
    if sj_batch(relaxed[local]).min() > sj_batch(points[local]).min() + FLAT_FILL:
        points = relaxed
    # Only around the folds (a big face has thousands of quads that are fine): the quads
    # within UNTANGLE_RINGS of an inverted one move, the nodes on that patch's rim stay.
    near = sj_batch(points[local]) <= FLAT_FILL
    if not near.any():
        return points
    for _ in range(UNTANGLE_RINGS):
        touched = np.zeros(len(points), dtype=bool)
        touched[local[near].ravel()] = True
        near = touched[local].any(axis=1)
    rim = np.zeros(len(points), dtype=bool)
    rim[local[~near].ravel()] = True
    return improve_worst(points, local[near], fixed | rim, passes=UNTANGLE_PASSES, share=1.0)


def _laplacian(points, quads, fixed, iterations) -> np.ndarray:
    """Plain (unguarded) Laplacian moves of the nodes not fixed."""
    edges, degree = edge_graph(quads, len(points))
    free = ~fixed & (degree > 0)
    x = points.copy()
    for _ in range(iterations):
        x[free] = neighbour_means(x, edges, degree)[free]
    return x


def _coons(bottom, top, left, right) -> np.ndarray:
    """Transfinite interpolation with arc-length parameters from the four sides."""
    def frac(p):
        c = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(p, axis=0).T))])
        return c / c[-1] if c[-1] > 0 else np.linspace(0, 1, len(p))

    ub, ut, vl, vr = frac(bottom), frac(top), frac(left), frac(right)
    n, m = len(bottom) - 1, len(left) - 1
    vj = np.linspace(0, 1, m + 1)[None, :]
    ui = np.linspace(0, 1, n + 1)[:, None]
    u = (1 - vj) * ub[:, None] + vj * ut[:, None]
    v = (1 - ui) * vl[None, :] + ui * vr[None, :]
    u, v = u[..., None], v[..., None]
    p00, p10, p01, p11 = bottom[0], bottom[-1], top[0], top[-1]
    return ((1 - v) * bottom[:, None, :] + v * top[:, None, :]
            + (1 - u) * left[None, :, :] + u * right[None, :, :]
            - ((1 - u) * (1 - v) * p00 + u * (1 - v) * p10 + (1 - u) * v * p01 + u * v * p11))


def scaled_jacobians(nodes, quads) -> np.ndarray:
    """DESIGN.md: per quad, min over corners of (a x b) / (|a||b|), a to next, b to previous."""
    return sj_batch(nodes[quads])


def smooth(nodes, quads, fixed, iterations: int = SMOOTH_ITERATIONS) -> np.ndarray:
    """Guarded Laplacian smoothing of the free nodes."""
    if not len(quads):
        return nodes
    edges, degree = edge_graph(quads, len(nodes))
    free = ~fixed & (degree > 0)
    x = nodes.copy()
    span = float(np.ptp(x, axis=0).max())
    quality = scaled_jacobians(x, quads)
    for _ in range(iterations):
        proposal = x.copy()
        proposal[free] = neighbour_means(x, edges, degree)[free]
        new_quality = scaled_jacobians(proposal, quads)
        # The margin keeps rounding noise from deciding (a turned copy must decide alike).
        bad = new_quality < np.minimum(quality, SMOOTH_FLOOR) - 1e-12
        for _ in range(10):
            if not bad.any():
                break
            undo = np.unique(quads[bad].ravel())
            proposal[undo] = x[undo]
            new_quality = scaled_jacobians(proposal, quads)
            bad = new_quality < np.minimum(quality, SMOOTH_FLOOR) - 1e-12
        if bad.any():
            break
        moved = float(np.hypot(*(proposal - x).T).max())
        x, quality = proposal, new_quality
        if moved < 1e-12 * span:
            break
    return x
