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
    node = int(own[k])
    index = np.nonzero(on_loop)[0][k]
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
