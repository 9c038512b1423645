"""Training labels from streamlines, as the paper's §2.2 and Figure 3 define them.

A frame vector is 1 when its node belongs to a background triangle that a streamline
crosses and it is the one of the node's two vectors more aligned with the streamline
there; every other vector is 0.  Crossed triangles are found by walking samples spaced
an eighth of an element along each streamline, so none is skipped.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from .background import BackgroundMesh
from .meshwalk import MeshWalker

SAMPLES_PER_ELEMENT = 8


def resample(points: np.ndarray, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """Points every ``spacing`` along a polyline, with the unit direction there."""
    seg = np.diff(points, axis=0)
    length = np.hypot(seg[:, 0], seg[:, 1])
    keep = length > 0
    seg, length, starts = seg[keep], length[keep], points[:-1][keep]
    if not len(seg):
        return np.empty((0, 2)), np.empty((0, 2))
    cum = np.concatenate([[0.0], np.cumsum(length)])
    s = np.linspace(0.0, cum[-1], max(2, int(np.ceil(cum[-1] / spacing)) + 1))
    idx = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(seg) - 1)
    frac = (s - cum[idx]) / length[idx]
    direction = seg[idx] / length[idx, None]
    return starts[idx] + frac[:, None] * seg[idx], direction


def frame_labels(mesh: BackgroundMesh, frames: np.ndarray, streamlines) -> np.ndarray:
    """(N, 2) int8 labels for the two frame vectors (v1, v2) of every node."""
    if not len(streamlines):
        return np.zeros((mesh.n_nodes, 2), dtype=np.int8)
    return crossed_labels(mesh.walker, mesh.centroid_tree, mesh.element_size, frames,
                          [line.points for line in streamlines])


def crossed_labels(walker: MeshWalker, centroid_tree: cKDTree, h: float, frames: np.ndarray,
                   polylines) -> np.ndarray:
    """The rule of frame_labels for any polylines (streamlines, or the coarse rays of
    infer.rays), on a mesh already prepared for point location (a walker, and a KD-tree
    of the triangle centroids to start each walk from)."""
    labels = np.zeros((len(walker.nodes), 2), dtype=np.int8)
    polylines = [p for p in polylines if len(p) > 1]
    if not polylines:
        return labels
    spacing = h / SAMPLES_PER_ELEMENT
    pts, dirs = zip(*(resample(p, spacing) for p in polylines))
    pts, dirs = np.concatenate(pts), np.concatenate(dirs)
    guess = centroid_tree.query(pts)[1]
    tri, _, _ = walker.locate(guess, pts)
    inside = tri >= 0
    nodes = walker.triangles[tri[inside]]  # (S, 3)
    d = np.repeat(dirs[inside][:, None, :], 3, axis=1)  # (S, 3, 2)
    v1, v2 = frames[nodes, 0:2], frames[nodes, 2:4]
    a1 = np.abs((v1 * d).sum(axis=2))
    a2 = np.abs((v2 * d).sum(axis=2))
    column = (a2 > a1).astype(np.int64)
    labels[nodes.ravel(), column.ravel()] = 1
    return labels
