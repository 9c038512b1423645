"""Segment counts per arc of the T-mesh: an integer program, solved exactly.

Opposite sides of every block must hold the same number of segments for a structured
map; among all counts that satisfy this, take the one closest to length / target size in
the sum of squared deviations.  Boundary arcs get at least one segment, except short ones
that do not join two corners (see collapse.py); streamline arcs may get none (Lyon,
Campen, Kobbelt 2021; QuadWild's Bi-MDF): two separatrices that run side by side then
become one mesh line and the strip between them vanishes (see collapse.py), where counts
of at least one made the program infeasible or the strip a row of slivers.  A collapse
may not put two anchors (boundary nodes, singular points) in one place; such a solution
is refused by a row "one of the merges on the path between them does not happen" and the
program solved again.

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

import dataclasses
import functools
from dataclasses import dataclass

import numpy as np
from scipy.optimize import Bounds, LinearConstraint, milp
from scipy.sparse import coo_matrix

from .collapse import conflicts, merges, node_layout, stretches
from .crossings import cumulative_length, point_at
from .partition_types import Partition, PartitionError
from .partition_types import free_blocks as given_up  # _solve's free_blocks is a flag


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
        # The point half-way along (a mirrored copy samples its curves the other way
        # round: the middle sample would be another point).
        pts = partition.edge_points(e, True)
        cum = cumulative_length(pts)
        middle = point_at(pts, cum, 0.5 * float(cum[-1]))
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
    """Sparse matrix of rows given as {column: coefficient} (zero coefficients left out,
    as a row's dict may hold an edge on both sides of a block).  Built from triplets: a
    lil_matrix filled entry by entry took half of the program's time on a partition of
    300 blocks, solved again for every round of conflict rows."""
    rows, columns, values = [], [], []
    for r, row in enumerate(entries):
        for column, value in row.items():
            if value:
                rows.append(r)
                columns.append(column)
                values.append(value)
    matrix = coo_matrix((np.array(values, dtype=float), (np.array(rows, dtype=np.int64),
                                                         np.array(columns, dtype=np.int64))),
                        shape=(len(entries), n_columns))
    return matrix.tocsr()


SHORT_BOUNDARY_ARC = 0.5  # element sizes: a boundary arc this short may get no segment
MIN_LOOP_SEGMENTS = 3


def _least_count(edge, size: float, fixed) -> int:
    """0 for a streamline arc and for a short boundary arc that does not join two fixed
    vertices (corners, singular points): its ends may become one mesh node (collapse.py),
    as when the trace that made one of them had ended on the corner beside it; else 1."""
    if not edge.is_boundary:
        return 0
    short = round(edge.length / size, 9) <= SHORT_BOUNDARY_ARC
    return 0 if short and not (edge.a in fixed and edge.b in fixed) else 1


def _loop_rings(partition: Partition, position) -> list:
    """Variable positions of each boundary loop's edges."""
    rings: dict = {}
    for e, edge in enumerate(partition.edges):
        if edge.is_boundary:
            rings.setdefault(edge.pieces[0].loop, []).append(int(position[e]))
    return [rings[li] for li in sorted(rings)]


def _merge_variables(partition: Partition, position, reason) -> tuple:
    """The count variables (geometric positions) a merge (collapse.merges) hangs on."""
    if reason[0] == "edge":
        return (int(position[reason[1]]),)
    _, b, pair = reason  # both sides of the pair: which is side 0 depends on the pose
    sides = partition.blocks[b].sides
    return tuple(sorted({int(position[e]) for side in (sides[pair], sides[pair + 2])
                         for e, _ in side}))


MAX_ROUNDS = 30  # conflict rows added one solve at a time
MIN_FREE_FACE_HALVES = 3  # a free face's outline at half resolution: at least a triangle
TIE_BREAK = 1e-6  # squared segments per segment, at most: orders equal-cost counts
FREE_BLOCK_COST = 1000.0  # a block given up to unstructured quads, in squared segments


@dataclass
class _Problem:
    """The integer program's pieces: columns are n (E), c (E), m (E), z (B)."""

    n_edges: int
    n_blocks: int
    rows: list  # (coefficients {column: value}, lower, upper)

    @property
    def n_columns(self) -> int:
        return 3 * self.n_edges + self.n_blocks

    def constraint(self, extra=()):
        rows = list(self.rows) + list(extra)
        return LinearConstraint(_rows([r for r, _, _ in rows], self.n_columns),
                                [lo for _, lo, _ in rows], [up for _, _, up in rows])


class InfeasibleCounts(PartitionError):
    """No counts make every block's opposite sides equal (HiGHS: the model is infeasible).
    ``forbidden``: the rows against pinches the solves had found by then (variable
    positions, at least one segment among each row's): they hold for any counts, blocks
    given up or not, so a program that may give blocks up starts from them.  ``edges``:
    the partition's edges those rows' variables count."""

    def __init__(self, message: str, forbidden=(), edges=frozenset()):
        super().__init__(message)
        self.forbidden = [list(row) for row in forbidden]
        self.edges = frozenset(edges)


MILP_SECONDS = 60.0  # per solve; past it the counts are refused, not taken unproven


def quantize(partition: Partition, size: float,
             time_limit: float = MILP_SECONDS) -> np.ndarray:
    """Integer segment count per edge of the partition, every block kept (PartitionError
    when no counts make all blocks' opposite sides equal)."""
    counts, freed = _solve(partition, size, time_limit, free_blocks=False)
    return counts


def quantize_freeing(partition: Partition, size: float,
                     time_limit: float = MILP_SECONDS) -> tuple:
    """(counts, blocks given up): every block kept where that is feasible (the usual
    case, and the faster program), else as few given up as the traces force."""
    try:
        return _solve(partition, size, time_limit, free_blocks=False)
    except InfeasibleCounts as exc:
        forbidden, pinched = exc.forbidden, exc.edges
    # The blocks the elastic program leaves unequal, and those whose counts the rows
    # against pinches hold (balanced, the counts may still pinch: nist_ctc04_plate's
    # 2048-node layout once squared holes' lines left straight, all blocks balanced, a
    # pinch in every balanced solution).
    suspects = set(_unequal_blocks(partition, size, time_limit) or ()) \
        | blocks_on(partition, pinched)
    if suspects:
        # The fewest blocks to give up, chosen among those and their neighbours only:
        # exact where it counts, and fast (a program that may give up any of 1000 blocks
        # ran past a minute, perforated_plate's finer layout; any of nist_ctc04_plate's
        # 189, 3 s a solve and 7 solves).
        try:
            return _solve(partition, size, time_limit,
                          free_blocks=_with_neighbours(partition, suspects),
                          forbidden=forbidden)
        except PartitionError:
            pass
    return _solve(partition, size, time_limit, free_blocks=True, forbidden=forbidden)


def blocks_on(partition: Partition, edges) -> set:
    """The blocks with a side on one of ``edges``."""
    return {b for b, block in enumerate(partition.blocks)
            if any(e in edges for side in block.sides for e, _ in side)}


def _with_neighbours(partition: Partition, blocks) -> set:
    """The blocks and every block that shares an edge with one of them."""
    edges = {e for b in blocks for side in partition.blocks[b].sides for e, _ in side}
    return set(blocks) | blocks_on(partition, edges)


@dataclass
class _Base:
    """What both programs share: the variables' order, bounds and the rows that hold
    whatever the blocks do (columns n, c, m as in _Problem)."""

    position: np.ndarray  # edge e is variable position[e]
    block_order: list  # blocks in the order their rows and columns come
    target: np.ndarray  # length / size per variable
    lower: np.ndarray
    upper: np.ndarray
    free_edges: list  # variables of free-face edges: even counts of at least 2
    rows: list


def _base(partition: Partition, size: float) -> _Base:
    n_edges = len(partition.edges)
    order = geometric_order(partition, size)
    position = np.empty(n_edges, dtype=np.int64)
    position[order] = np.arange(n_edges)
    block_order = sorted(range(len(partition.blocks)), key=lambda b: sorted(
        int(position[e]) for side in partition.blocks[b].sides for e, _ in side))
    # Rounded: a turned or rescaled copy must pose the very same problem (near-ties at
    # n + 0.5 would otherwise be broken by rounding noise).
    target = np.round(np.array([partition.edges[e].length / size for e in order]), 9)
    fixed = set(partition.fixed) | set(partition.singular)
    lower = np.array([_least_count(partition.edges[e], size, fixed) for e in order])
    free_edges = sorted({int(position[e]) for face in partition.free_faces
                         for ring in face.rings for e, _ in ring})
    lower[free_edges] = 2
    upper = np.maximum(4 * np.ceil(target) + 4, 8).astype(int)
    rows = [({v: 1, 2 * n_edges + v: -2}, 0, 0) for v in free_edges]
    for ring in _loop_rings(partition, position):
        if any(lower[v] == 0 for v in ring):  # no loop shrinks to fewer than 3 segments
            rows.append((dict.fromkeys(ring, 1), MIN_LOOP_SEGMENTS, np.inf))
    for face in partition.free_faces:
        for ring in face.rings:  # a hole as well as the outline (a 2-point hole is none)
            row: dict = {}
            for e, _ in ring:
                column = 2 * n_edges + int(position[e])
                row[column] = row.get(column, 0) + 1
            rows.append((row, MIN_FREE_FACE_HALVES, np.inf))
    return _Base(position, block_order, target, lower, upper, free_edges, rows)


def _pair_row(block, pair: int, position) -> dict:
    """Side ``pair`` minus its opposite side, as coefficients of the count variables."""
    row: dict = {}
    for e, _ in block.sides[pair]:
        row[int(position[e])] = row.get(int(position[e]), 0) + 1
    for e, _ in block.sides[pair + 2]:
        row[int(position[e])] = row.get(int(position[e]), 0) - 1
    return row


ELASTIC_ROUNDS = 20  # rounds of giving up the blocks the least violation leaves unequal


def _unequal_blocks(partition: Partition, size: float, time_limit: float):
    """Blocks (indices) to give up so that every other block's opposite sides can be
    equal, found fast; [] if none is left unequal, None if a solve or the rounds run out
    (the exact program decides then).

    Each round solves the elastic program: integer counts that violate the blocks'
    equalities as little as possible, a slack s_b >= |side - opposite side| per block,
    sum of s_b least (no big-M: its relaxation is tight, and it solves in a fraction of
    a second where the program that chooses the fewest blocks to give up took over a
    minute on 1000 blocks).  The blocks left unequal are given up; their edges then need
    even counts (free faces), which may leave others unequal: the next round sees that.
    The rounds end when no block is left unequal, which the exact program then confirms.
    """
    n_edges = len(partition.edges)
    chosen: list = []
    current, alive = partition, list(range(len(partition.blocks)))  # alive[k]: current k's index
    for _ in range(ELASTIC_ROUNDS):
        base = _base(current, size)
        n_blocks = len(current.blocks)
        s_col = {b: 3 * n_edges + k for k, b in enumerate(base.block_order)}
        rows = list(base.rows)
        for b in base.block_order:
            for pair in (0, 1):
                row = _pair_row(current.blocks[b], pair, base.position)
                rows.append(({**row, s_col[b]: -1}, -np.inf, 0))
                rows.append(({**row, s_col[b]: 1}, 0, np.inf))
        problem = _Problem(n_edges, n_blocks, rows)
        cost = np.concatenate([np.zeros(3 * n_edges), np.ones(n_blocks)])
        integrality = np.concatenate([np.ones(n_edges), np.zeros(n_edges),
                                      np.ones(n_edges), np.zeros(n_blocks)])
        bounds = Bounds(np.concatenate([base.lower, np.zeros(2 * n_edges + n_blocks)]),
                        np.concatenate([base.upper, np.zeros(n_edges), base.upper,
                                        np.full(n_blocks, np.inf)]))
        result = milp(cost, constraints=[problem.constraint()], integrality=integrality,
                      bounds=bounds, options={"time_limit": time_limit, "mip_rel_gap": 0.0})
        if result.status != 0:
            return None
        unequal = sorted(b for b in range(n_blocks) if result.x[s_col[b]] > 0.5)
        if not unequal:
            return chosen
        gone = set(unequal)
        chosen.extend(alive[b] for b in unequal)
        alive = [i for k, i in enumerate(alive) if k not in gone]
        current = given_up(current, unequal, "unequal")
    return None


def _solve(partition: Partition, size: float, time_limit: float, free_blocks,
           forbidden=()) -> tuple:
    """(counts per edge, indices of blocks given up to free faces).

    Edges of free faces get an even count of at least 2 (n_e = 2 m_e): their quads come
    from a mesh of the face at half resolution, subdivided (free_faces.py).  A block may be
    given up (z_b = 1, at FREE_BLOCK_COST): its equalities are lifted and its edges become
    free-face edges.  That keeps the program feasible by construction: with every block
    given up, each edge takes 2 or more even segments and nothing else constrains it.  The
    solver gives up as few blocks as the traces force (numerical traces satisfy the
    equalities only approximately; chains of T-junctions can contradict each other).
    ``forbidden``: rows against pinches found by an earlier solve of this partition
    (InfeasibleCounts.forbidden), posed from the start instead of found again.
    """
    n_edges, n_blocks = len(partition.edges), len(partition.blocks)
    if n_edges == 0:
        return np.zeros(0, dtype=int), []
    base = _base(partition, size)
    position, block_order, lower, upper = base.position, base.block_order, base.lower, base.upper
    free_edges = base.free_edges
    z_col = {b: 3 * n_edges + k for k, b in enumerate(block_order)}
    big = float(upper.max()) * (n_edges + 1)
    rows = list(base.rows)
    for b in block_order:
        block = partition.blocks[b]
        z = z_col[b]
        for pair in (0, 1):
            row = _pair_row(block, pair, position)
            # |plus - minus| <= big z_b
            rows.append(({**row, z: -big}, -np.inf, 0))
            rows.append(({**row, z: big}, 0, np.inf))
        variables = sorted({int(position[e]) for side in block.sides for e, _ in side})
        for v in variables:
            if v in free_edges:
                continue
            # given up: n_v even (|n_v - 2 m_v| <= big (1 - z_b)) and at least 2
            rows.append(({v: 1, 2 * n_edges + v: -2, z: big}, -np.inf, big))
            rows.append(({v: 1, 2 * n_edges + v: -2, z: -big}, -big, np.inf))
            rows.append(({v: 1, z: -(2 - lower[v])}, lower[v], np.inf))
        rows.append(({**{2 * n_edges + v: 1 for v in variables}, z: -MIN_FREE_FACE_HALVES},
                     0, np.inf))
    problem = _Problem(n_edges, n_blocks, rows)
    secants = _secant_rows(base.target, lower, upper, problem.n_columns)
    # Ties broken by the geometric order: equal-cost counts (two edges of one length
    # whose sum is fixed) would otherwise go to whichever the solver meets first, and a
    # turned copy, whose rows come in another order, got the other one.
    tie_break = TIE_BREAK * np.arange(1, n_edges + 1) / n_edges
    cost = np.concatenate([tie_break, np.ones(n_edges), np.zeros(n_edges),
                           np.full(n_blocks, FREE_BLOCK_COST)])
    integrality = np.concatenate([np.ones(n_edges), np.zeros(n_edges), np.ones(n_edges),
                                  np.ones(n_blocks)])
    # free_blocks: True (any block may be given up), False (none) or the blocks that may
    may = range(n_blocks) if free_blocks is True else set(free_blocks or ())
    z_upper = np.array([1.0 if b in may else 0.0 for b in block_order])
    bounds = Bounds(np.concatenate([lower, np.zeros(2 * n_edges), np.zeros(n_blocks)]),
                    np.concatenate([upper, np.full(n_edges, np.inf), upper,
                                    z_upper]))
    forbidden = [list(row) for row in forbidden]  # rows: >= 1 segment among these variables
    # ... and rows against stretches, kept only while they cost no block (a chain of
    # short arcs may have no other way to close than to collapse); not posed at all
    # where blocks are given up already (they would be dropped again after a solve,
    # and the next solve is the one before them: two of nist_ctc04_plate's 3 s solves).
    unstretched, stretching = [], True
    for _ in range(MAX_ROUNDS):
        extra = [(dict.fromkeys(f, 1), 1, np.inf) for f in forbidden + unstretched]
        result = milp(cost, constraints=[secants, problem.constraint(extra)],
                      integrality=integrality, bounds=bounds,
                      options={"time_limit": time_limit, "mip_rel_gap": 0.0})
        if unstretched and (result.status == 2 or (
                result.status == 0 and (result.x[3 * n_edges:] > 0.5).any())):
            unstretched, stretching = [], False  # they cost blocks: as before them
            continue
        if result.x is None and result.status == 2:  # proven infeasible
            edge_of = np.argsort(position)  # variable v counts edge edge_of[v]
            raise InfeasibleCounts(f"no segment counts make opposite block sides equal "
                                   f"({result.message})", forbidden,
                                   {int(edge_of[v]) for row in forbidden for v in row})
        if result.status != 0:  # a time-limited answer would depend on the machine's speed
            raise PartitionError(f"the segment-count program found no proven optimum "
                                 f"within {time_limit:g} s ({result.message})")
        counts = np.rint(result.x[:n_edges]).astype(int)[position]
        freed = sorted(b for b in range(n_blocks) if result.x[z_col[b]] > 0.5)
        kept = [b for b in range(n_blocks) if b not in set(freed)]
        reduced = dataclasses.replace(partition, blocks=[partition.blocks[b] for b in kept])
        layout = node_layout(reduced, counts, size if stretching else None)
        variables_of = functools.partial(_merge_variables, reduced, position)
        found_merges = merges(reduced, layout, counts)
        found = conflicts(layout, found_merges, key=variables_of)
        stretched = stretches(layout, found_merges, key=variables_of) if not found else []
        if not found and (not stretched or freed):
            return counts, freed
        for reasons in found:
            forbidden.append(sorted({v for reason in reasons for v in variables_of(reason)}))
        for reasons in stretched:
            unstretched.append(sorted({v for reason in reasons for v in variables_of(reason)}))
    raise PartitionError("the segment counts keep pinching the domain (merging boundary "
                         "nodes or singular points)")
