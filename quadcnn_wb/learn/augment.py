"""Augmentation as the paper's §2.2 lists it: rotation, smooth deformation, and random
movement of mesh points (so every sample has its own background mesh).

Rotation (and mirroring) act on the exact domain before meshing, so the field, streamlines
and labels are recomputed for the new geometry.  Point jitter moves interior background
nodes before the field is solved.  The smooth deformation bends the finished sample
(positions and frames) and is the only augmentation that is not a true field of some
domain: it teaches tolerance to shapes slightly off the family.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..core.field.background import BackgroundMesh
from ..infer.encoding import canonical_angle

JITTER = 0.15  # interior node movement, in element sizes
DEFORMATION = 0.03  # smooth displacement amplitude, in domain diagonals


def jitter_nodes(mesh: BackgroundMesh, rng: np.random.Generator) -> BackgroundMesh:
    """Move interior nodes randomly, never inverting a triangle."""
    moving = np.ones(mesh.n_nodes, dtype=bool)
    moving[mesh.boundary_nodes] = False
    step = JITTER * mesh.element_size * rng.uniform(-1, 1, size=(mesh.n_nodes, 2))
    step[~moving] = 0.0
    nodes = mesh.nodes.copy()
    for _ in range(6):
        trial = nodes + step
        a, b, c = (trial[mesh.triangles[:, k]] for k in range(3))
        area = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
        bad = np.unique(mesh.triangles[area <= 0].ravel())
        if not len(bad):
            nodes = trial
            break
        step[bad] *= 0.0
    return dataclasses.replace(mesh, nodes=nodes)


def smooth_deformation(nodes, theta, labels, rng: np.random.Generator):
    """Bend a sample by a smooth random displacement; frames follow the Jacobian.

    A frame vector turned past ±45° changes which of the two is v1, so the labels swap
    with it: `labels` holds pairs of columns (a value for v1, one for v2), each pair swaps.
    """
    size = float(np.hypot(*np.ptp(nodes, axis=0)))
    k = rng.uniform(1.0, 3.0, size=2) * 2 * np.pi / size
    phase = rng.uniform(0, 2 * np.pi, size=2)
    amp = DEFORMATION * size * rng.uniform(0.3, 1.0, size=2)
    x, y = nodes[:, 0], nodes[:, 1]
    out = nodes + np.column_stack([amp[0] * np.sin(k[0] * y + phase[0]),
                                   amp[1] * np.sin(k[1] * x + phase[1])])
    # Jacobian of the map: [[1, a0 k0 cos(k0 y + p0)], [a1 k1 cos(k1 x + p1), 1]].
    dxdy = amp[0] * k[0] * np.cos(k[0] * y + phase[0])
    dydx = amp[1] * k[1] * np.cos(k[1] * x + phase[1])
    v = np.column_stack([np.cos(theta), np.sin(theta)])
    moved = np.column_stack([v[:, 0] + dxdy * v[:, 1], dydx * v[:, 0] + v[:, 1]])
    angle = np.arctan2(moved[:, 1], moved[:, 0])
    new_theta = canonical_angle(angle)
    turned = np.abs(((angle - new_theta) + np.pi / 2) % np.pi - np.pi / 2) > np.pi / 4
    labels = labels.copy()
    pairs = labels[turned].reshape(int(turned.sum()), labels.shape[1] // 2, 2)
    labels[turned] = pairs[:, :, ::-1].reshape(int(turned.sum()), labels.shape[1])
    return out, new_theta, labels
