"""An independent checker for quad meshes: it shares no code with the pipeline, so a
mesh the pipeline wrongly believes valid is still caught (tests, robustness campaign)."""

from __future__ import annotations

import math
from collections import Counter

import numpy as np


class MeshDefect(AssertionError):
    """What is wrong with a mesh that claims to be a valid conforming all-quad mesh."""


def _require(condition, message: str) -> None:
    if not condition:
        raise MeshDefect(message)


def quad_areas(nodes, quads):
    p = nodes[quads]
    x, y = p[..., 0], p[..., 1]
    return 0.5 * np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1)


def corner_crosses(nodes, quads):
    p = nodes[quads]
    out = []
    for k in range(4):
        a = p[:, (k + 1) % 4] - p[:, k]
        b = p[:, (k - 1) % 4] - p[:, k]
        out.append(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
    return np.stack(out, axis=1)


def chord_allowance(nodes, arcs, tol) -> float:
    """Area between each circular arc (center, radius) and the chords through the mesh
    nodes that lie on it: what a valid mesh may miss under curved boundaries."""
    total = 0.0
    for center, radius in arcs:
        d = np.hypot(*(nodes - center).T)
        on = np.abs(d - radius) <= tol
        if on.sum() < 2:
            continue
        angles = np.sort(np.arctan2(*(nodes[on] - center).T[::-1]))
        gaps = np.diff(np.concatenate([angles, [angles[0] + 2 * math.pi]]))
        gaps = gaps[gaps < math.pi]  # steps between neighbours on the arc
        total += float(np.sum(0.5 * radius ** 2 * (gaps - np.sin(gaps))))
    return total


def cut_corner_allowance(nodes, boundary_edges, vertices, tol) -> float:
    """Area a mesh may miss or add where its boundary edges cut across the domain's
    vertices that hold no mesh node (a step or bump below the element size, read as part
    of a side): twice the triangle between each such vertex and the boundary edge nearest
    it (an edge across one vertex cuts off that triangle; across a step's two corners,
    the two triangles less what they share)."""
    if not len(vertices) or not boundary_edges:
        return 0.0
    a = nodes[[e[0] for e in boundary_edges]]
    b = nodes[[e[1] for e in boundary_edges]]
    ab = b - a
    total = 0.0
    for v in np.asarray(vertices, dtype=float):
        if np.min(np.hypot(*(nodes - v).T)) <= tol:
            continue  # a mesh node sits on it
        t = np.clip(np.einsum("ij,ij->i", v - a, ab) / np.einsum("ij,ij->i", ab, ab), 0, 1)
        k = int(np.argmin(np.hypot(*(a + t[:, None] * ab - v).T)))
        u, w = a[k] - v, b[k] - v
        total += abs(u[0] * w[1] - u[1] * w[0])  # twice the triangle
    return total


def check_quad_mesh(nodes, quads, domain_area, on_boundary, arcs=None, vertices=()):
    """Raise MeshDefect unless a valid conforming all-quad mesh; returns the boundary edges.

    on_boundary(point) -> bool tells whether a point lies on the domain boundary; arcs,
    (center, radius) of the curved boundary pieces, bound the area chords may cut off
    (arcs None, for a mesh of unknown curves: 1 % of the domain is allowed), and so do the
    domain's vertices (cut_corner_allowance).
    """
    _require(quads.ndim == 2 and quads.shape[1] == 4, "not an (n, 4) array of quads")
    _require(quads.min() >= 0 and quads.max() < len(nodes), "a quad refers to no node")
    _require(all(len(set(q)) == 4 for q in quads.tolist()), "repeated node in a quad")
    _require(np.all(corner_crosses(nodes, quads) > 0), "inverted or degenerate corner")
    areas = quad_areas(nodes, quads)
    _require(np.all(areas > 0), "clockwise quad")
    edges = Counter()
    directed = {}
    for q in quads.tolist():
        for k in range(4):
            a, b = q[k], q[(k + 1) % 4]
            edges[(min(a, b), max(a, b))] += 1
            directed[(min(a, b), max(a, b))] = (a, b)
    _require(max(edges.values()) <= 2, "an edge shared by more than two quads")
    boundary_edges = [e for e, c in edges.items() if c == 1]
    for a, b in boundary_edges:
        _require(on_boundary(nodes[a]) and on_boundary(nodes[b]), "hanging node / gap")
    # No overlaps: the quads tile exactly the polygon their boundary edges enclose ...
    enclosed = sum(0.5 * (nodes[a][0] * nodes[b][1] - nodes[b][0] * nodes[a][1])
                   for a, b in (directed[e] for e in boundary_edges))
    _require(math.isclose(areas.sum(), enclosed, rel_tol=1e-9),
             "quads overlap (their areas exceed the area they enclose)")
    # ... which differs from the domain only by chords under curved boundaries.
    tol = 1e-9 * math.sqrt(domain_area)
    allowance = (chord_allowance(nodes, arcs, tol) * 1.001 + 1e-9 * domain_area
                 + cut_corner_allowance(nodes, boundary_edges, vertices, tol)) \
        if arcs is not None else 1e-2 * domain_area
    _require(abs(areas.sum() - domain_area) <= allowance,
             "the quads do not cover the domain's area")
    used = np.unique(quads)
    _require(len(used) == len(nodes), "unused nodes")
    return boundary_edges


def check_domain_mesh(domain, mesh) -> None:
    """check_quad_mesh for a mesh of a Domain: boundary nodes within 1e-9 of the part's
    size of its exact curves, area allowance from its arcs and its vertices.  Raises
    MeshDefect."""
    tol = 1e-9 * domain.size
    curves = [c for loop in domain.loops for c in loop]

    def on_boundary(p):
        return any(np.hypot(*(c.point(c.project(p)) - p)) <= tol for c in curves)

    arcs = [(np.asarray(c.center), c.radius) for c in curves if hasattr(c, "radius")]
    vertices = [c.p0 for c in curves if getattr(c, "kind", "") != "circle"]
    check_quad_mesh(mesh.nodes, mesh.quads, domain.area, on_boundary, arcs, vertices)
