"""A quad mesh's edges as a graph: what Laplacian smoothing (quadmesh.smooth) and the
straightening's averaging (straighten.py) both read."""

from __future__ import annotations

import numpy as np


def edge_graph(quads, n: int) -> tuple:
    """(unique quad edges (E, 2), number of edges at each of the n nodes)."""
    edges = np.concatenate([quads[:, [k, (k + 1) % 4]] for k in range(4)])
    edges = np.unique(np.sort(edges, axis=1), axis=0)
    return edges, np.bincount(edges.ravel(), minlength=n).astype(float)


def neighbour_means(x, edges, degree) -> np.ndarray:
    """Mean of each node's edge neighbours (rows of nodes on no edge are 0/0)."""
    # bincount adds in the order of its input, as np.add.at did (first every edge's
    # first node, then every second node): the same sums, bit for bit, several times
    # faster (smoothing calls this hundreds of times a mesh).
    at = np.concatenate([edges[:, 0], edges[:, 1]])
    other = np.concatenate([edges[:, 1], edges[:, 0]])
    n = len(x)
    summed = np.stack([np.bincount(at, weights=x[other, k], minlength=n)
                       for k in range(x.shape[1])], axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return summed / degree[:, None]
