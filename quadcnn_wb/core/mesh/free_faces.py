"""Unstructured quads for the faces of a partition that are no blocks.

A face with other than four corners, or one that turns back, cannot take a structured
map; rather than give up the blocks of the whole domain for it, only that face is filled
by gmsh, with the nodes its neighbours already put on its sides, so the mesh stays
conforming.  gmsh's all-quad route is a triangle/quad mesh recombined (blossom) and then
subdivided once, which halves every boundary segment; so the face is handed to gmsh at
half resolution (every other side node, each side count even: quantize.py), and the
midpoints gmsh inserts are replaced by the side nodes in between.

The outline goes to gmsh in the part's canonical pose (pose.py) and starting at a vertex
chosen from the geometry, so a turned, moved or mirrored copy of the part gets the same
quads there too.
"""

from __future__ import annotations

import gmsh
import numpy as np

from ..gmsh_geometry import unit as rounded_unit
from ..gmsh_session import gmsh_session, silenced_stdio
from ..layout.partition_types import PartitionError, fmt, inside_polygon

KEY_DIGITS = 7  # rounding of the keys that choose where the outline starts


# gmsh's planar algorithm and recombination, tried in turn on a face whose quads stay
# inverted (quadmesh.py): Frontal-Delaunay for quads with blossom first; on the faces of
# the corpus that fold, each of the others fills a different share of them.
FILL_METHODS = ((8, 1), (6, 0), (1, 1), (8, 0), (5, 1))


def free_face_fills(rings, pose):
    """Fills of the region bounded by ``rings``, one per FILL_METHODS entry, each
    (interior points (P, 2), quads (Q, 4)); the outline is checked and put in the
    canonical pose once for all of them.  ``rings``:
    the outer polygon (counter-clockwise) and the holes in it (clockwise), each of an
    even number of points, not repeated at the end.  Quads index the rings' points in
    order (outer first) as 0 .. N-1 and the interior points as N .. N+P-1.  The first
    method's failure is raised; a later one that fails is skipped."""
    rings = [np.asarray(r, dtype=float) for r in rings]
    centre = rings[0].mean(axis=0)
    if any(len(r) % 2 for r in rings) or len(rings[0]) < 6:
        raise PartitionError(f"a free face near {fmt(centre)} has {len(rings[0])} side "
                             "segments (an even number >= 6 is needed)")
    posed = []  # per ring: its unit-pose points in walking order, their parity
    for ring in rings:
        # Rounded as the background's geometry is: a turned copy hands gmsh the very same
        # numbers, not numbers a rounding error apart (which changed the quads).
        unit = rounded_unit(pose.to_unit(ring))
        order = np.arange(len(ring))
        if pose.mirrored:  # the canonical pose of a mirror image runs the other way round
            order = np.concatenate([[0], np.arange(len(ring) - 1, 0, -1)])
        posed.append((unit, order, _corner_parity(unit[order])))
    units, orders = _simple_half_rings(posed)
    if units is None:
        raise PartitionError(f"a free face near {fmt(centre)} touches or crosses itself: "
                             "no polygon to fill")
    offset = sum(len(r) for r in rings)
    order = np.concatenate(orders)
    for method, (algorithm, recombination) in enumerate(FILL_METHODS):
        try:
            interior, quads = _gmsh_fill(units, algorithm, recombination)
        except PartitionError:
            if method == 0:
                raise
            continue
        quads = np.where(quads < offset, order[np.minimum(quads, offset - 1)], quads)
        yield pose.from_unit(interior), quads


def _simple_half_rings(posed) -> tuple:
    """(unit rings, index orders) of the first choice of every-other nodes whose coarse
    rings gmsh can mesh, or (None, None): the sharpest-turn parity of every ring first,
    then each ring's other parity, then all of them flipped.  In a thin curved strip
    (a gear's tooth gap) one parity's chords cross the other side where the other's
    do not."""
    n = len(posed)
    flips = [()] + [(k,) for k in range(n)] + ([tuple(range(n))] if n > 1 else [])
    for flipped in flips:
        units, orders, offset = [], [], 0
        for k, (unit, order, parity) in enumerate(posed):
            order = np.roll(order, -(1 - parity if k in flipped else parity))
            order = np.roll(order, -_start(unit[order]))
            units.append(unit[order])
            orders.append(order + offset)
            offset += len(unit)
        if rings_are_simple([u[0::2] for u in units]):
            return units, orders
    return None, None


def free_face_quads(rings, pose) -> tuple:
    """The first of free_face_fills: gmsh's default algorithm."""
    return next(free_face_fills(rings, pose))




SIMPLE_TOL = 1e-6  # share of the polygon's size: closer than this is touching


def rings_are_simple(rings) -> bool:
    """The outer ring counter-clockwise, the holes clockwise and inside it, and no two
    sides of any rings crossing or touching except neighbours of one ring at their shared
    end: a region gmsh can mesh (it may hang on anything else)."""
    rings = [np.asarray(r, dtype=float) for r in rings]
    every = np.concatenate(rings)
    tol = SIMPLE_TOL * float(np.ptp(every, axis=0).max())
    a, b, ring_of, index = [], [], [], []
    for k, p in enumerate(rings):
        n = len(p)
        area = 0.5 * float(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))
        if n < 3 or not (area > tol * tol if k == 0 else -area > tol * tol):
            return False
        if k and not inside_polygon(rings[0], p[0]):
            return False
        a.append(p)
        b.append(np.roll(p, -1, axis=0))
        ring_of.append(np.full(n, k))
        index.append(np.arange(n))
    a, b = np.concatenate(a), np.concatenate(b)
    ring_of, index = np.concatenate(ring_of), np.concatenate(index)
    size = np.array([len(r) for r in rings])[ring_of]
    i, j = np.triu_indices(len(a), 1)
    same = ring_of[i] == ring_of[j]
    step = (index[j] - index[i]) % size[i]
    keep = ~(same & ((step == 1) | (step == size[i] - 1)))  # neighbours share an end
    i, j = i[keep], j[keep]

    def orient(o, u, v):
        return (u[..., 0] - o[..., 0]) * (v[..., 1] - o[..., 1]) \
            - (u[..., 1] - o[..., 1]) * (v[..., 0] - o[..., 0])

    d1, d2 = orient(a[i], b[i], a[j]), orient(a[i], b[i], b[j])
    d3, d4 = orient(a[j], b[j], a[i]), orient(a[j], b[j], b[i])
    if np.any((d1 * d2 < 0) & (d3 * d4 < 0)):
        return False
    # Touching: an end of one side within tol of the other side.
    for ends, side in (((a[j], b[j]), i), ((a[i], b[i]), j)):
        for q in ends:
            u, v = a[side], b[side]
            d = v - u
            t = np.clip(np.sum((q - u) * d, axis=1) / np.maximum(np.sum(d * d, axis=1),
                                                                  1e-300), 0.0, 1.0)
            if np.any(np.hypot(*(u + t[:, None] * d - q).T) <= tol):
                return False
    return True


TURN_TIE = 1e-6  # radians: turns closer than this are equally sharp


def _corner_parity(unit: np.ndarray) -> int:
    """0 or 1: which every-other nodes of the ring gmsh gets at half resolution, so that
    its sharpest turns are among them.  A sharp turn left to a middle node (a notch's
    tip between two coarse nodes) is cut off by gmsh's chord, and the quads pulled out
    to it fold.  Turns within TURN_TIE count as equal, and a tie keeps the ring's own
    start, so round-off in a turned copy cannot flip the choice."""
    before = unit - np.roll(unit, 1, axis=0)
    after = np.roll(unit, -1, axis=0) - unit
    turn = np.abs(np.arctan2(before[:, 0] * after[:, 1] - before[:, 1] * after[:, 0],
                             np.sum(before * after, axis=1)))
    even, odd = (np.sort(turn[p::2])[::-1] for p in (0, 1))
    for a, b in zip(even, odd):
        if abs(a - b) > TURN_TIE:
            return int(b > a)
    return 0


def _start(unit: np.ndarray) -> int:
    """An even index chosen from the geometry: the coarse point farthest from the centre
    (ties: the larger angle key), rounded so round-off cannot move it."""
    coarse = unit[0::2]
    rel = coarse - coarse.mean(axis=0)
    keys = [(round(float(np.hypot(*r)), KEY_DIGITS), round(float(np.arctan2(r[1], r[0])), 3))
            for r in rel]
    return 2 * max(range(len(keys)), key=lambda k: keys[k])


BEND_TOL = 1e-3  # a side node this far off its chord (share of the chord) bends the side


def _bends(a, middle, b) -> bool:
    chord = b - a
    length = float(np.hypot(*chord))
    off = abs(float(chord[0] * (middle[1] - a[1]) - chord[1] * (middle[0] - a[0]))) / length
    return off > BEND_TOL * length


def _gmsh_fill(units, algorithm: int, recombination: int) -> tuple:
    """gmsh's quads for the rings at half resolution; local ids as free_face_quads."""
    with gmsh_session() as session:
        geo = gmsh.model.geo
        loops, point_of, line_of, offset = [], {}, {}, 0
        for unit in units:
            coarse = unit[0::2]
            m = len(coarse)
            seg = np.hypot(*(np.roll(coarse, -1, axis=0) - coarse).T)
            sizes = 0.5 * (seg + np.roll(seg, 1))
            points = [geo.addPoint(float(x), float(y), 0.0, float(s))
                      for (x, y), s in zip(coarse, sizes)]
            # Each side through the side node between its ends, so that gmsh meshes the
            # true (curved) outline and its midpoint is that node's place.
            middles = [geo.addPoint(float(x), float(y), 0.0, float(s))
                       for (x, y), s in zip(unit[1::2], seg)]
            lines = [geo.addSpline([points[k], middles[k], points[(k + 1) % m]])
                     if _bends(coarse[k], unit[2 * k + 1], coarse[(k + 1) % m])
                     else geo.addLine(points[k], points[(k + 1) % m]) for k in range(m)]
            loops.append(geo.addCurveLoop(lines))
            point_of.update({tag: offset + 2 * k for k, tag in enumerate(points)})
            line_of.update({tag: offset + 2 * k + 1 for k, tag in enumerate(lines)})
            offset += len(unit)
        surface = geo.addPlaneSurface(loops)
        geo.synchronize()
        for line in line_of:
            gmsh.model.mesh.setTransfiniteCurve(line, 2)
        for name, value in (("Mesh.Algorithm", algorithm), ("Mesh.RecombineAll", 1),
                            ("Mesh.RecombinationAlgorithm", recombination),
                            ("Mesh.SubdivisionAlgorithm", 1), ("Mesh.MeshSizeFromPoints", 1),
                            ("Mesh.MeshSizeFromCurvature", 0),
                            ("Mesh.MeshSizeExtendFromBoundary", 1)):
            session.set(name, value)
        centre = units[0].mean(axis=0)
        try:
            with silenced_stdio():
                gmsh.model.mesh.generate(2)
        except Exception as exc:  # gmsh reports every failure as a bare Exception
            raise PartitionError(f"gmsh could not fill a free face near {fmt(centre)}: "
                                 f"{exc}") from None
        index = {}
        for tag, local in point_of.items():
            index[int(gmsh.model.mesh.getNodes(0, tag)[0][0])] = local
        for tag, local in line_of.items():
            inner = gmsh.model.mesh.getNodes(1, tag)[0]
            if len(inner) != 1:
                raise PartitionError("gmsh split a free face's side other than in two")
            index[int(inner[0])] = local
        tags, xyz, _ = gmsh.model.mesh.getNodes(2, surface)
        interior = xyz.reshape(-1, 3)[:, :2].copy()
        for k, tag in enumerate(tags):
            index[int(tag)] = offset + k
        types, _, node_tags = gmsh.model.mesh.getElements(2, surface)
        if list(types) != [3]:
            raise PartitionError(f"gmsh left triangles in a free face near {fmt(centre)}")
        quads = np.array([index[int(t)] for t in node_tags[0]], dtype=np.int64).reshape(-1, 4)
    return interior, quads
