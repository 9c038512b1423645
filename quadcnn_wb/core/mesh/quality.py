"""Mesh quality as DESIGN.md defines it: scaled Jacobian, irregular vertices, counts."""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..input.corners import corner_quads, interior_angle
from .quadmesh import scaled_jacobians


def boundary_quads_expected(domain, nodes, boundary) -> np.ndarray:
    """Quads a regular boundary node has: input.corners.corner_quads, 2 on smooth stretches."""
    expected = np.where(boundary, 2, 4)
    tree = cKDTree(nodes)
    tol = 1e-9 * domain.size
    for loop in domain.loops:
        for k, curve in enumerate(loop):
            if curve.kind == "circle":
                continue
            dist, node = tree.query(curve.p0)
            if dist <= tol:
                angle = interior_angle(loop[k - 1], curve)
                expected[node] = corner_quads(angle)
    return expected


def irregular_vertices(quads, n_nodes: int, expected) -> np.ndarray:
    """Nodes whose number of quads differs from what a regular vertex there would have."""
    count = np.bincount(quads.ravel(), minlength=n_nodes)
    used = count > 0
    return np.nonzero(used & (count != expected))[0]


def min_scaled_jacobian(mesh) -> float:
    sj = scaled_jacobians(mesh.nodes, mesh.quads)
    return float(sj.min()) if len(sj) else 0.0


def longest_edge(mesh) -> float:
    """The longest quad edge: what the share, the irregular count and the scaled Jacobian
    all miss, a block whose counts follow a short side and so ignore the requested size
    across it (socket_bearing's block over its slot: one segment across, 7.6 sizes long,
    scaled Jacobian 0.84)."""
    if not len(mesh.quads):
        return 0.0
    corners = mesh.nodes[mesh.quads]
    edges = np.roll(corners, -1, axis=1) - corners
    return float(np.hypot(edges[..., 0], edges[..., 1]).max())


def structured_share(mesh) -> float:
    """Share of the quads that lie in blocks (block -1: a quad in no block)."""
    return float(np.mean(mesh.block_of_quad >= 0)) if len(mesh.quads) else 0.0


def mesh_quality(domain, mesh) -> dict:
    sj = scaled_jacobians(mesh.nodes, mesh.quads)
    expected = boundary_quads_expected(domain, mesh.nodes, mesh.boundary)
    irregular = irregular_vertices(mesh.quads, len(mesh.nodes), expected)
    return {
        "min_scaled_jacobian": float(sj.min()) if len(sj) else 0.0,
        "mean_scaled_jacobian": float(sj.mean()) if len(sj) else 0.0,
        "irregular_vertices": int(len(irregular)),
        "blocks": int(len(np.unique(mesh.block_of_quad[mesh.block_of_quad >= 0]))),
        "quads": int(len(mesh.quads)),
    }
