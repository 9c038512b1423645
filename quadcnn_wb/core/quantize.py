"""Segment counts per partition edge: the paper's integer program, solved exactly.

Opposite sides of every block must hold the same number of segments for a structured
map; among all counts n_e >= 1 that satisfy this, take the one closest (sum of absolute
deviations) to length / target size.  `scipy.optimize.milp` solves it exactly; the
absolute values are split into auxiliary variables t_e >= |n_e - L_e / H|.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import Bounds, LinearConstraint, milp
from scipy.sparse import lil_matrix

from .partition import Partition, PartitionError


def side_counts(partition: Partition, counts) -> list:
    """Segments on each of the four sides of every block."""
    return [[sum(int(counts[e]) for e, _ in side) for side in block.sides]
            for block in partition.blocks]


def quantize(partition: Partition, size: float, time_limit: float = 20.0) -> np.ndarray:
    """Integer segment count per edge of the partition."""
    n_edges = len(partition.edges)
    if n_edges == 0:
        return np.zeros(0, dtype=int)
    target = np.array([e.length / size for e in partition.edges])
    rows = lil_matrix((2 * len(partition.blocks), 2 * n_edges))
    for b, block in enumerate(partition.blocks):
        for pair in (0, 1):
            for e, _ in block.sides[pair]:
                rows[2 * b + pair, e] += 1
            for e, _ in block.sides[pair + 2]:
                rows[2 * b + pair, e] -= 1
    dev = lil_matrix((2 * n_edges, 2 * n_edges))
    for e in range(n_edges):
        dev[2 * e, e], dev[2 * e, n_edges + e] = -1, 1  # t - n >= -target
        dev[2 * e + 1, e], dev[2 * e + 1, n_edges + e] = 1, 1  # t + n >= target
    lower = np.empty(2 * n_edges)
    lower[0::2], lower[1::2] = -target, target
    constraints = [LinearConstraint(dev.tocsr(), lower, np.inf)]
    if partition.blocks:
        constraints.append(LinearConstraint(rows.tocsr(), 0, 0))
    cost = np.concatenate([np.zeros(n_edges), np.ones(n_edges)])
    integrality = np.concatenate([np.ones(n_edges), np.zeros(n_edges)])
    upper = np.concatenate([np.maximum(4 * np.ceil(target) + 4, 8), np.full(n_edges, np.inf)])
    result = milp(cost, constraints=constraints, integrality=integrality,
                  bounds=Bounds(np.concatenate([np.ones(n_edges), np.zeros(n_edges)]), upper),
                  options={"time_limit": time_limit})
    if result.x is None:
        raise PartitionError(f"no segment counts make opposite block sides equal "
                             f"({result.message})")
    return np.rint(result.x[:n_edges]).astype(int)
