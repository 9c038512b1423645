"""Segment counts per partition edge: the paper's integer program, solved exactly.

Opposite sides of every block must hold the same number of segments for a structured
map; among all counts n_e >= 1 that satisfy this, take the one closest (sum of absolute
deviations) to length / target size.
`scipy.optimize.milp` solves it exactly; the absolute values are split into auxiliary
variables t_e >= |n_e - L_e / H|.
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


def geometric_order(partition: Partition, size: float) -> np.ndarray:
    """Edges sorted by what a turned, mirrored or moved copy of the part shares: length,
    then distance of the middle from the partition's centre.

    The integer program often has many optima (an edge opposite a much longer one may take
    any count between their ideal ones at equal cost), and the solver's pick depends on
    the order of the variables; posing it in this order gives every copy the same counts.
    """
    centre = partition.vertices.mean(axis=0) if len(partition.vertices) else np.zeros(2)
    keys = []
    for e, edge in enumerate(partition.edges):
        pts = partition.edge_points(e, True)
        middle = pts[len(pts) // 2]
        keys.append((round(edge.length / size, 6),
                     round(float(np.hypot(*(middle - centre))) / size, 6)))
    return np.array(sorted(range(len(keys)), key=lambda e: keys[e]), dtype=np.int64)


def quantize(partition: Partition, size: float, time_limit: float = 20.0) -> np.ndarray:
    """Integer segment count per edge of the partition."""
    n_edges = len(partition.edges)
    if n_edges == 0:
        return np.zeros(0, dtype=int)
    order = geometric_order(partition, size)
    position = np.empty(n_edges, dtype=np.int64)
    position[order] = np.arange(n_edges)  # edge e is variable position[e]
    # Rounded: a turned or rescaled copy must pose the very same problem (near-ties at
    # n + 0.5 would otherwise be broken by rounding noise).
    target = np.round(np.array([partition.edges[e].length / size for e in order]), 9)
    equalities = []  # (variable positions with +1, with -1), in a geometric order too
    for block in partition.blocks:
        for pair in (0, 1):
            plus = sorted(int(position[e]) for e, _ in block.sides[pair])
            minus = sorted(int(position[e]) for e, _ in block.sides[pair + 2])
            equalities.append((plus, minus) if plus < minus else (minus, plus))
    equalities.sort()
    rows = lil_matrix((len(equalities), 2 * n_edges))
    for r, (plus, minus) in enumerate(equalities):
        for v in plus:
            rows[r, v] += 1
        for v in minus:
            rows[r, v] -= 1
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
    return np.rint(result.x[:n_edges]).astype(int)[position]
