"""Grid lines that leave the boundary square to it, in blocks whose quads are sheared.

A block's side nodes are spread evenly along each side.  Where a band two elements
thick runs round a tight bend and on along a straight (the raised letters of NIST CTC
01: an S whose inner bends are a fifth as long as its outer ones), the inner side's
nodes run ahead of the outer side's past the bend and every quad of the straight is
sheared alike (0.51 all along it).  The max-min moves (improve.py) cannot mend that:
moving one boundary node along its curve squares one quad and shears the next, so each
step loses.  What mends it is moving all of them together: every boundary node slides
to the foot of the grid line that leaves it (the nearest point of its curve to the
node across its inward edge), the interior nodes go to the mean of their neighbours,
and the two are repeated until the lines stand square to the boundary.  Only in the
blocks with a quad under improve.SLIDE_BELOW (even spacing along the boundary is worth
more elsewhere: a stress peak is read from the nodes on a hole's rim), and kept only
if the worst quad there gets better.  All nodes move at once each round (no visiting
order), so a turned or mirrored copy moves alike.
"""

from __future__ import annotations

import numpy as np

from .edge_graph import edge_graph, neighbour_means
from .improve import SLIDE_BELOW, sj_batch
from .orientation import tiles_exactly

STRAIGHTEN_ROUNDS = 40  # slide-and-average rounds (the letters' S settles in about 30)
RELAXATION = 0.5  # of the way to the foot a boundary node moves each round
FOOT_SAMPLES = 16  # points of the curve between a node's neighbours searched for the foot
FOOT_REFINES = 3  # times the search narrows round the best sample
KEEP_CLEAR = 0.25  # of its first spacing a slid node keeps from either neighbour
GUARD = 0.8  # a round may lower no quad below this or the region's worst
GUARD_TRIES = 10
STILL = 1e-3  # of the median node spacing: a round that moves no node farther ends them
# A mesh this bad somewhere is left as it is: a near-flat quad is a block folding (the
# rounds free it or cut across it: rounds.blocks_and_mesh), not one sheared by its
# side nodes, and squaring the lines round it would hide it from them (blend_pocket_kink
# at diameter/100: 0.154 straightened, kept, where the rounds give 0.878).
FOLDED_BELOW = 0.2


def straightened(nodes, quads, fixed, slides: dict, owner) -> np.ndarray:
    """``nodes`` with the sheared blocks' grid lines squared to the boundary (see the
    module's docstring); ``slides``: improve.BoundarySlide by node id (updated where
    the result is kept); ``owner``: the block of each quad (-1: a free face's)."""
    x = np.asarray(nodes, dtype=float)
    sj = sj_batch(x[quads])
    bad_blocks = np.unique(owner[(sj < SLIDE_BELOW) & (owner >= 0)])
    if not len(bad_blocks) or not slides or sj.min() < FOLDED_BELOW:
        return x
    region = np.isin(owner, bad_blocks)
    region_quads = quads[region]
    in_region = np.zeros(len(x), dtype=bool)
    in_region[region_quads.ravel()] = True
    # Nodes on a free face or a block left out stay: the region's edge is fixed.
    outside = np.zeros(len(x), dtype=bool)
    outside[quads[~region].ravel()] = True
    free = in_region & ~fixed & ~outside
    sliding = np.array(sorted(v for v in slides if in_region[v] and not outside[v]),
                       dtype=np.int64)
    across = _across(region_quads, sliding)
    keep = across >= 0
    sliding, across = sliding[keep], across[keep]
    if not len(sliding) and not free.any():
        return x
    edges, degree = edge_graph(region_quads, len(x))
    curves = [slides[int(v)].curve for v in sliding]
    by_curve: dict = {}
    for k, curve in enumerate(curves):
        by_curve.setdefault(id(curve), []).append(k)
    groups = [np.array(members) for members in by_curve.values()]  # nodes on one curve
    slots, fixed_t = _neighbour_slots(slides, sliding)
    ts = np.array([slides[int(v)].t for v in sliding])

    def bounds(ts):
        ends = np.where(slots >= 0, ts[np.maximum(slots, 0)], fixed_t)
        return ends.min(axis=1), ends.max(axis=1)

    # Each node keeps KEEP_CLEAR of its first spacing from either neighbour: the two
    # move at once, each at most RELAXATION of the way, so neither passes the other.
    lo, hi = bounds(ts)
    clear = KEEP_CLEAR * 0.5 * (hi - lo)
    still = STILL * float(np.median(hi - lo)) if len(ts) else 0.0
    y = x.copy()
    quality = sj_batch(y[region_quads])
    for _ in range(STRAIGHTEN_ROUNDS):
        lo, hi = bounds(ts)
        feet = _feet(curves, groups, ts, lo + clear, hi - clear, y[across])
        proposed = ts + RELAXATION * (feet - ts)
        proposal = y.copy()
        for members in groups:
            proposal[sliding[members]] = curves[members[0]].point(proposed[members])
        proposal[free] = neighbour_means(proposal, edges, degree)[free]
        # No quad may fall below the region's worst (or GUARD): the nodes of one that
        # would stay where they were this round.
        floor = min(GUARD, float(quality.min()))
        for _ in range(GUARD_TRIES):
            new_quality = sj_batch(proposal[region_quads])
            bad = new_quality < floor - 1e-12
            if not bad.any():
                break
            undo = np.unique(region_quads[bad].ravel())
            proposal[undo] = y[undo]
            back = np.isin(sliding, undo)
            proposed[back] = ts[back]
        if bad.any():
            break
        moved = float(np.hypot(*(proposal - y).T).max())
        y, ts, quality = proposal, proposed, new_quality
        if moved <= still:
            break
    before = sj[region].min()
    after = quality.min()
    # Positive corners do not exclude a quad slid over another (orientation.tiles_exactly).
    if not round(float(after), 9) > round(float(before), 9) or \
            (not tiles_exactly(y, region_quads) and tiles_exactly(x, region_quads)):
        return x
    for k, v in enumerate(sliding):
        slides[int(v)].t = float(ts[k])
    return y


def _neighbour_slots(slides, sliding):
    """Per sliding node, its two neighbours along the boundary: their index among the
    sliding nodes (-1: none) and, where they do not slide here, the arc length that
    bounds it (a neighbour's that stays, or its stretch's end)."""
    index = {int(v): k for k, v in enumerate(sliding)}
    slots = np.full((len(sliding), 2), -1, dtype=np.int64)
    fixed_t = np.zeros((len(sliding), 2))
    for k, v in enumerate(sliding):
        slide = slides[int(v)]
        for side, (node, end) in enumerate(((slide.before, slide.t_before),
                                            (slide.after, slide.t_after))):
            if node is None:
                fixed_t[k, side] = end
            elif node in index:
                slots[k, side] = index[node]
            else:
                fixed_t[k, side] = slides[node].t
    return slots, fixed_t


def _across(quads, sliding) -> np.ndarray:
    """For each sliding node, the node across its inward edge: the edge its two quads
    share (-1 where it has not exactly two quads, or they share no other node)."""
    out = np.full(len(sliding), -1, dtype=np.int64)
    index = {int(v): k for k, v in enumerate(sliding)}
    owners: dict = {}
    for q, quad in enumerate(quads):
        for c in range(4):
            k = index.get(int(quad[c]))
            if k is not None:
                owners.setdefault(k, []).append(q)
    for k, qs in owners.items():
        if len(qs) != 2:
            continue
        v = int(sliding[k])
        a, b = (set(_edge_ends(quads[q], v)) for q in qs)
        shared = a & b
        if len(shared) == 1:
            out[k] = shared.pop()
    return out


def _edge_ends(quad, v: int) -> tuple:
    c = int(np.nonzero(quad == v)[0][0])
    return int(quad[(c + 1) % 4]), int(quad[(c - 1) % 4])


def _feet(curves, groups, ts, lo, hi, targets) -> np.ndarray:
    """Per sliding node, the arc length in [lo, hi] whose point is nearest its target
    (where lo < hi; else where it is): a grid search narrowed round the best sample,
    for all the nodes on one curve at once."""
    out = ts.copy()
    steps = np.linspace(0.0, 1.0, FOOT_SAMPLES)
    for members in groups:
        a, b = lo[members], hi[members]
        open_ = a < b
        members, a, b = members[open_], a[open_], b[open_]
        if not len(members):
            continue
        for _ in range(FOOT_REFINES + 1):
            grid = a[:, None] + (b - a)[:, None] * steps[None, :]
            points = curves[members[0]].point(grid.ravel()).reshape(len(members), -1, 2)
            d = np.hypot(*np.moveaxis(points - targets[members][:, None, :], -1, 0))
            best = grid[np.arange(len(members)), np.argmin(np.round(d, 12), axis=1)]
            step = (b - a) / (FOOT_SAMPLES - 1)
            a, b = np.maximum(a, best - step), np.minimum(b, best + step)
        out[members] = best
    return out
