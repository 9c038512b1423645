"""What counts as a corner of a boundary loop, and its angle on the domain's side.

The background mesh makes every corner a node that can start separatrices, the topology
signature counts corners to decide which model fits a domain, and the quality measure
expects a number of quads at a corner node, and the cross field turns at a corner by
what is left of the tangent's turn after those quads: all of them must mean the same
joints, the same angles and the same quads per corner, so the rules live here once.
"""

from __future__ import annotations

import math

import numpy as np

from .curves import cross2

CORNER_MIN_TURN = 1e-4  # radians; smaller tangent breaks are smooth joins, not corners
QUARTER_TIE = 1e-6  # quarter turns: angles this close to an odd multiple of 45° are that tie


# radians: a tangent that turns back this nearly is read by the curves.  Not round-off
# only: CAD kernels keep tangent curves tangent to about 1e-5 (a crank web's horn, two
# B-splines meeting at a cusp, turned back by 1e-5 the wrong way and read as a notch).
REVERSAL = 1e-3
REVERSAL_PROBE = 0.05  # ... a point this share of the shorter curve from the joint


def interior_angle(incoming, outgoing) -> float:
    """Angle on the domain's side (the left) between consecutive curves at their joint.

    Where the tangent turns back (tangent curves meeting at a tip), the sign of the
    turn is round-off: the same horn read 0° in one copy of a part and 360° in another
    (a JSON round trip of a blend plate: a cusp's kite against three corner lines of no
    length, and the whole face fell back).  There the curves themselves tell: the tip
    is a cusp (0°) where the outgoing curve lies to the left of the incoming one, the
    domain's side, and a 360° notch otherwise."""
    t_in, t_out = incoming.tangent(1.0), outgoing.tangent(0.0)
    turn = math.atan2(cross2(t_in, t_out), float(np.dot(t_in, t_out)))
    if math.pi - abs(turn) < REVERSAL:
        reach = REVERSAL_PROBE * min(incoming.length, outgoing.length)
        before = incoming.point(1.0 - reach / incoming.length)
        after = outgoing.point(reach / outgoing.length)
        turn = math.pi if cross2(t_in, np.asarray(after) - np.asarray(before)) > 0.0 \
            else -math.pi
    return math.pi - turn


def is_corner(angle: float) -> bool:
    """Whether a joint of this interior angle is a corner (not a smooth join)."""
    return abs(angle - math.pi) > CORNER_MIN_TURN


def nearest_quarters(angle: float) -> int:
    """The interior angle in whole quarter turns, the nearest count: how far the cross
    field turns at the corner is the tangent's turn less these (0 for a cusp, whose
    cross carries on as on a smooth stretch).

    A 135° chamfer or a 225° notch lies exactly between two counts, and which one the
    part's angle rounds to must not hang on round-off (a turned copy's 135° is
    134.99999999° or 135.00000001°): an angle within QUARTER_TIE of such a tie is the tie,
    which goes to the even count, as Python's round() does (135° and 225°: 2, a flat join;
    315°: 4), but for 45°, which gets the one quad a corner cannot do without."""
    quarters = angle / (math.pi / 2)
    if at_quarter_tie(angle):
        nearest_half = math.floor(quarters) + 0.5
        return 1 if nearest_half == 0.5 else int(round(nearest_half))
    return int(round(quarters))


def at_quarter_tie(angle: float) -> bool:
    """Whether the angle is (within QUARTER_TIE) an odd multiple of 45°."""
    quarters = angle / (math.pi / 2)
    return abs(quarters - math.floor(quarters) - 0.5) <= QUARTER_TIE


def corner_quads(angle: float, odd_tie: bool = False) -> int:
    """Quads a regular mesh puts at a corner of this interior angle (at least one);
    ``odd_tie``: a tie that takes its odd count (odd_ties)."""
    return max(1, corner_quarters(angle, odd_tie))


def corner_quarters(angle: float, odd_tie: bool = False) -> int:
    """nearest_quarters, or a tie's odd count where ``odd_tie`` (odd_ties)."""
    return tie_quarters(angle) if odd_tie else nearest_quarters(angle)


def tie_quarters(angle: float) -> int:
    """The odd one of the two counts a tie (at_quarter_tie) lies between: 1 for 135°,
    3 for 225° and 315°."""
    return int(math.floor(angle / (math.pi / 2))) | 1


def odd_ties(domain) -> frozenset:
    """(loop, curve) of the joints at the start of those curves whose tie goes to the odd
    count: in a loop whose corners, rounded the even way, leave it R quarter turns short
    of its whole turn (4 for the outer loop, -4 for a hole), and whose ties that turn the
    other way to make up for it are exactly |R| in number, those ties take the odd
    count, so the loop's corners account for the whole turn and the field needs no
    singular point for it.  A pocket's round corner of four arcs ending on its wall at
    225° (held-out 0016: 45° of arc and a 45° kink) left one valence-5 point in a wall a
    fifth of an element thick, and strips of unstructured quads round it.  Where more
    ties could make up for it than needed (a rectangle with one corner chamfered), which
    of them should cannot be said, and none does.  Not 45° (one quad already, the count
    a corner cannot do without)."""
    out = set()
    for li, loop in enumerate(domain.loops):
        short, helping = tie_shortfall(li, loop)
        if helping and len(helping) == abs(short):
            out.update((li, k) for k in helping)
    return frozenset(out)


def tie_shortfall(li: int, loop) -> tuple[int, list]:
    """(R, joints): the quarter turns R by which a loop's corners, rounded the even way,
    fall short of its whole turn, and the tie joints (odd multiples of 45°, not 45°)
    whose odd count would make up one quarter of it each (odd_ties, features' chamfers)."""
    if len(loop) < 2:
        return 0, []
    short = 4 if li == 0 else -4
    helping = []
    for k in range(len(loop)):
        angle = interior_angle(loop[k - 1], loop[k])
        if not is_corner(angle):
            continue
        quarters = nearest_quarters(angle)
        short -= 2 - quarters
        if at_quarter_tie(angle) and angle > math.pi / 2:
            helping.append((k, tie_quarters(angle) - quarters))
    return short, [k for k, step in helping if short and step == (-1 if short > 0 else 1)]
