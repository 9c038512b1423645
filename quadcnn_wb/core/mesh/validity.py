"""Whether a quad mesh is one: no inverted quad, no overlap, no gap inside, no hole
covered.  The layout rounds (core.rounds) free or cut what fails these, and the
pipeline hands no mesh out that fails them."""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from .orientation import tiles_exactly
from .quadmesh import scaled_jacobians


def crossing_quads(nodes, quads) -> np.ndarray:
    """Quads with an edge that crosses another quad's edge: where blocks fold over each
    other though every element is positive."""
    directed = np.concatenate([quads[:, [k, (k + 1) % 4]] for k in range(4)])
    owner = np.tile(np.arange(len(quads)), 4)
    key = np.sort(directed, axis=1)
    edges = np.unique(key, axis=0)
    a, b = nodes[edges[:, 0]], nodes[edges[:, 1]]
    reach = float(np.hypot(*(b - a).T).max())
    pairs = cKDTree(0.5 * (a + b)).query_pairs(reach, output_type="ndarray")
    i, j = pairs[:, 0], pairs[:, 1]
    shared = (edges[i][:, :, None] == edges[j][:, None, :]).any(axis=(1, 2))
    i, j = i[~shared], j[~shared]

    def orient(o, u, v):
        return (u[:, 0] - o[:, 0]) * (v[:, 1] - o[:, 1]) - (u[:, 1] - o[:, 1]) * (v[:, 0] - o[:, 0])

    cross = (orient(a[i], b[i], a[j]) * orient(a[i], b[i], b[j]) < 0) \
        & (orient(a[j], b[j], a[i]) * orient(a[j], b[j], b[i]) < 0)
    hit = np.zeros(len(edges), dtype=bool)
    hit[i[cross]] = hit[j[cross]] = True
    bad = np.zeros(len(quads), dtype=bool)
    _, inverse = np.unique(key, axis=0, return_inverse=True)
    bad[owner[hit[inverse.ravel()]]] = True
    return bad


def is_valid_mesh(mesh) -> bool:
    """No inverted or degenerate quad, no overlap, no gap, no hole filled over."""
    return bool(len(mesh.quads)) and scaled_jacobians(mesh.nodes, mesh.quads).min() > 0 \
        and tiles_exactly(mesh.nodes, mesh.quads) \
        and free_edges_on_boundary(mesh.quads, mesh.boundary) \
        and boundary_on_free_edges(mesh.quads, mesh.boundary)


def free_edges_on_boundary(quads, boundary) -> bool:
    """Every edge used by one quad only joins two boundary nodes: no gap inside.

    (A gap's own edges enclose a negative area, so tiles_exactly cannot see it.)"""
    directed = np.concatenate([quads[:, [k, (k + 1) % 4]] for k in range(4)])
    key = np.sort(directed, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    free = key[counts[inverse.ravel()] == 1]
    return bool(boundary[free].all())


def boundary_on_free_edges(quads, boundary) -> bool:
    """Every used boundary node is an end of an edge used by one quad only: no boundary
    loop lies inside the mesh (a hole filled over)."""
    directed = np.concatenate([quads[:, [k, (k + 1) % 4]] for k in range(4)])
    key = np.sort(directed, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    on_free = np.zeros(len(boundary), dtype=bool)
    on_free[key[counts[inverse.ravel()] == 1].ravel()] = True
    used = np.zeros(len(boundary), dtype=bool)
    used[quads.ravel()] = True
    return bool(np.all(on_free[boundary & used]))
