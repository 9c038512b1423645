"""Quads turned counter-clockwise: the orientation every quad mesh here is handed on in.

The block maps (quadmesh.py) and gmsh's quads (gmsh_quads.py) come out in either
orientation; scaled Jacobians, the exports and the FreeCAD mesh all read a quad's
corners counter-clockwise, so both pass their quads through the same rule.
"""

from __future__ import annotations

import numpy as np


def signed_areas(nodes: np.ndarray, quads: np.ndarray) -> np.ndarray:
    """(Q,) shoelace area of each quad: positive when its corners run counter-clockwise."""
    p = nodes[quads]
    return 0.5 * np.sum(p[:, :, 0] * np.roll(p[:, :, 1], -1, axis=1)
                        - np.roll(p[:, :, 0], -1, axis=1) * p[:, :, 1], axis=1)


def counter_clockwise_quads(nodes: np.ndarray, quads: np.ndarray) -> np.ndarray:
    """A copy of ``quads`` (Q, 4) with every clockwise quad's corners reversed."""
    area = signed_areas(nodes, quads)
    out = quads.copy()
    out[area < 0] = out[area < 0][:, ::-1]
    return out


def tiles_exactly(nodes, quads) -> bool:
    """No overlaps: the quads' areas add up to the area their free edges enclose.

    Positive corners alone do not exclude a block folded over its neighbour; this does.
    """
    area = float(signed_areas(nodes, quads).sum())
    directed = np.concatenate([quads[:, [k, (k + 1) % 4]] for k in range(4)])
    key = np.sort(directed, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    free = directed[counts[inverse.ravel()] == 1]
    a, b = nodes[free[:, 0]], nodes[free[:, 1]]
    enclosed = 0.5 * np.sum(a[:, 0] * b[:, 1] - b[:, 0] * a[:, 1])
    return bool(abs(area - enclosed) <= 1e-9 * max(abs(enclosed), 1e-300))
