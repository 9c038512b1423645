"""Segment counts per arc of the T-mesh: an integer program, solved exactly.

Opposite sides of every block must hold the same number of segments for a structured
map; among all counts that satisfy this, take the one closest to length / target size in
the sum of squared deviations.  Boundary arcs get at least one segment; streamline arcs
may get none (Lyon, Campen, Kobbelt 2021; QuadWild's Bi-MDF): two separatrices that run
side by side then become one mesh line and the strip between them vanishes (see
collapse.py), where counts of at least one made the program infeasible or the strip a
row of slivers.  A collapse may not put two anchors (boundary nodes, singular points) in
one place; such a solution is refused by a row "one of the merges on the path between
them does not happen" and the program solved again.

Feasibility.  In a T-mesh traced exactly in the field's seamless parametrization the arc
lengths in that parametrization are a positive real solution of the homogeneous equations;
rational points are dense in that solution space, so a scaled rational point is a
positive integer solution: the program is feasible, with every count >= 1 even, and the
zero counts only widen it.  Numerical traces satisfy the equations only approximately;
when they leave no solution, the solver says so and the caller knows the partition
failed (it never gets a silently wrong count).  (The sum of absolute deviations, used first, is
flat between the ideal counts of two opposite sides: a long arc opposite a short
streamline could take any count from the short side's to the long side's at equal cost,
and the solver's arbitrary pick, not the geometry, decided the mesh.)
`scipy.optimize.milp` solves it exactly: the convex cost c_e >= (n_e - L_e / H)^2 is
the upper envelope of its secants through consecutive integers, exact at every integer.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import Bounds, LinearConstraint, milp
from scipy.sparse import coo_matrix, lil_matrix

from ..partition import Partition, PartitionError
from .collapse import conflicts, merges, node_layout


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


def _secant_rows(target: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                 n_columns: int) -> LinearConstraint:
    """c_e - slope_k n_e >= f(k) - slope_k k for every secant of f(n) = (n - target_e)^2
    through n = k, k + 1 (k = lower_e .. upper_e - 1): at integer n the largest is f(n)."""
    n_edges = len(target)
    edge = np.repeat(np.arange(n_edges), upper - lower)
    k = np.concatenate([np.arange(lo, u) for lo, u in zip(lower, upper)]).astype(float)
    t = target[edge]
    slope = (k + 1 - t) ** 2 - (k - t) ** 2
    rows = np.arange(len(k))
    matrix = coo_matrix((np.concatenate([-slope, np.ones(len(k))]),
                         (np.concatenate([rows, rows]), np.concatenate([edge, n_edges + edge]))),
                        shape=(len(k), n_columns))
    return LinearConstraint(matrix.tocsr(), (k - t) ** 2 - slope * k, np.inf)


def _rows(entries: list, n_columns: int):
    """Sparse matrix of rows given as {column: coefficient}."""
    matrix = lil_matrix((len(entries), n_columns))
    for r, row in enumerate(entries):
        for column, value in row.items():
            matrix[r, column] += value
    return matrix.tocsr()


MAX_ROUNDS = 30  # conflict rows added one solve at a time
MIN_FREE_FACE_HALVES = 3  # a free face's outline at half resolution: at least a triangle


def quantize(partition: Partition, size: float, time_limit: float = 20.0) -> np.ndarray:
    """Integer segment count per edge of the partition (0 allowed on streamline arcs).

    Edges of free faces get an even count of at least 2 (n_e = 2 m_e): their quads come
    from a mesh of the face at half resolution, subdivided (free_faces.py).  Evenness
    keeps the program feasible: the block equalities are homogeneous, so twice any
    solution is a solution, and a free face is constrained by nothing else.
    """
    n_edges = len(partition.edges)
    if n_edges == 0:
        return np.zeros(0, dtype=int)
    order = geometric_order(partition, size)
    position = np.empty(n_edges, dtype=np.int64)
    position[order] = np.arange(n_edges)  # edge e is variable position[e]
    free_edges = sorted({int(position[e]) for face in partition.free_faces
                         for e, _ in face.halves})
    half_of = {v: 2 * n_edges + k for k, v in enumerate(free_edges)}  # m_e's column
    n_columns = 2 * n_edges + len(free_edges)
    # Rounded: a turned or rescaled copy must pose the very same problem (near-ties at
    # n + 0.5 would otherwise be broken by rounding noise).
    target = np.round(np.array([partition.edges[e].length / size for e in order]), 9)
    lower = np.array([1 if partition.edges[e].is_boundary else 0 for e in order])
    lower[free_edges] = 2
    equalities = []  # (variable positions with +1, with -1), in a geometric order too
    for block in partition.blocks:
        for pair in (0, 1):
            plus = sorted(int(position[e]) for e, _ in block.sides[pair])
            minus = sorted(int(position[e]) for e, _ in block.sides[pair + 2])
            equalities.append((plus, minus) if plus < minus else (minus, plus))
    equalities.sort()
    rows = []
    for plus, minus in equalities:
        row: dict = {}
        for v in plus:
            row[v] = row.get(v, 0) + 1
        for v in minus:
            row[v] = row.get(v, 0) - 1
        rows.append(row)
    rows.extend({v: 1, half_of[v]: -2} for v in free_edges)
    upper = np.maximum(4 * np.ceil(target) + 4, 8).astype(int)
    constraints = [_secant_rows(target, lower, upper, n_columns)]
    if rows:
        constraints.append(LinearConstraint(_rows(rows, n_columns), 0, 0))
    if partition.free_faces:
        at_least = [{half_of[int(position[e])]: 1 for e, _ in face.halves}
                    for face in partition.free_faces]
        constraints.append(LinearConstraint(_rows(at_least, n_columns),
                                            MIN_FREE_FACE_HALVES, np.inf))
    cost = np.concatenate([np.zeros(n_edges), np.ones(n_edges), np.zeros(len(free_edges))])
    integrality = np.concatenate([np.ones(n_edges), np.zeros(n_edges),
                                  np.ones(len(free_edges))])
    bounds = Bounds(np.concatenate([lower, np.zeros(n_edges), np.ones(len(free_edges))]),
                    np.concatenate([upper, np.full(n_edges, np.inf),
                                    np.full(len(free_edges), np.inf)]))
    forbidden = []  # rows: at least one segment among these variables
    for _ in range(MAX_ROUNDS):
        extra = []
        if forbidden:
            extra = [LinearConstraint(_rows([dict.fromkeys(f, 1) for f in forbidden],
                                            n_columns), 1, np.inf)]
        result = milp(cost, constraints=constraints + extra, integrality=integrality,
                      bounds=bounds, options={"time_limit": time_limit})
        if result.x is None:
            raise PartitionError(f"no segment counts make opposite block sides equal "
                                 f"({result.message})")
        if result.status != 0:  # a time-limited answer would depend on the machine's speed
            raise PartitionError(f"the segment-count program found no proven optimum "
                                 f"within {time_limit:g} s ({result.message})")
        counts = np.rint(result.x[:n_edges]).astype(int)[position]
        layout = node_layout(partition, counts)
        found = conflicts(layout, merges(partition, layout, counts))
        if not found:
            return counts
        for reasons in found:
            variables = set()
            for reason in reasons:
                if reason[0] == "edge":
                    variables.add(int(position[reason[1]]))
                else:
                    _, b, pair = reason
                    variables.update(int(position[e]) for e, _ in
                                     partition.blocks[b].sides[pair])
            forbidden.append(sorted(variables))
    raise PartitionError("the segment counts keep pinching the domain (merging boundary "
                         "nodes or singular points)")
