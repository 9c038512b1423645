"""An independent checker for quad meshes (it shares no code with the pipeline)."""

from __future__ import annotations

import math
from collections import Counter

import numpy as np


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


def check_quad_mesh(nodes, quads, domain_area, on_boundary):
    """Assert a valid conforming all-quad mesh; returns the boundary edge node pairs.

    on_boundary(point) -> bool tells whether a point lies on the domain boundary.
    """
    assert quads.ndim == 2 and quads.shape[1] == 4
    assert quads.min() >= 0 and quads.max() < len(nodes)
    assert all(len(set(q)) == 4 for q in quads.tolist()), "repeated node in a quad"
    assert np.all(corner_crosses(nodes, quads) > 0), "inverted or degenerate corner"
    areas = quad_areas(nodes, quads)
    assert np.all(areas > 0), "clockwise quad"
    edges = Counter()
    directed = {}
    for q in quads.tolist():
        for k in range(4):
            a, b = q[k], q[(k + 1) % 4]
            edges[(min(a, b), max(a, b))] += 1
            directed[(min(a, b), max(a, b))] = (a, b)
    assert max(edges.values()) <= 2, "an edge shared by more than two quads"
    boundary_edges = [e for e, c in edges.items() if c == 1]
    for a, b in boundary_edges:
        assert on_boundary(nodes[a]) and on_boundary(nodes[b]), "hanging node / gap"
    # No overlaps: the quads tile exactly the polygon their boundary edges enclose ...
    enclosed = sum(0.5 * (nodes[a][0] * nodes[b][1] - nodes[b][0] * nodes[a][1])
                   for a, b in (directed[e] for e in boundary_edges))
    assert math.isclose(areas.sum(), enclosed, rel_tol=1e-9)
    # ... which differs from the domain only by chords under curved boundaries.
    assert math.isclose(areas.sum(), domain_area, rel_tol=1e-2)
    used = np.unique(quads)
    assert len(used) == len(nodes), "unused nodes"
    return boundary_edges
