"""Boundary features below the element size, read as what they are at the mesh's scale.

A 0.6 mm step on a part meshed at 3.4 mm, a 1 mm fillet in a concave corner, a bump of a
tenth of an element: the mesh cannot follow their shape, and read literally they break
the layout.  Each corner of a step seeds its own streamlines, which then run a fraction
of an element from the boundary for the length of the part; a small fillet in a concave
corner is smooth, so no streamline leaves it and the face around it keeps a reflex
corner; a bump's tilted edge bends the cross field into a singular point.

So the boundary is read at the element's scale.  Its turns (each corner, and the whole
turn of each curve shorter than FEATURE sizes, of a concave fillet of radius under ROUND
sizes turning at most ROUND_SWEEP, or of a convex one of radius under CONVEX_ROUND sizes)
chain while each lies less than FEATURE sizes from the next; a chain holding more than one
turn, or a curve's, is one feature with the sum of its turns:
- a feature whose interior angle rounds to two quarter turns (a step, a bump) is flat:
  part of the side it sits on, with no corner, no corner streamlines and no vertex of the
  partition (the side's mesh nodes run over it);
- a feature that turns the other way by a quarter turn or more (a concave fillet of a
  radius under ROUND sizes, a concave chamfer under FEATURE sizes) is one concave corner,
  in the middle of the stretch, with that corner's streamlines.  Read as a curve, such a
  fillet needs a valence-5 singular point beside it, which the background cannot place
  well when the radius is a few elements or less (motor_c_plate's 1 mm fillets got
  none, the gear's root fillets a cluster); as a corner it needs none, and the quads at
  its middle meet at 45° to the curve plus what the curve turns under one element;
- a convex feature of CONVEX_MIN or more (a small fillet on a plate's corner, a stroke's
  rounded tip) is one convex corner in its middle, likewise.  Read as a curve, the face
  around it turned by a quarter within one partition edge and had three corners, and
  was split round an extra vertex (a rounded plate's corners came out as three squeezed
  quads each, worst scaled Jacobian 0.68 against 0.95 as corners); where a convex fillet
  is an element or more in radius, the field puts its valence-3 point in it instead;
- a sharper convex feature (a rib's or a stroke's round end, turning by more than
  pi - CONVEX_MIN, up to SLOT_SWEEP, between smooth joins) is two convex corners, each
  in the middle of its half, where its radius is under CONVEX_END sizes: the rib's end
  is square at the mesh's scale.  Read as a curve it needs two valence-3 points within
  an element of each other, which the background cannot place (corpus
  nist_ctc01_logo_bracket at its default size: the bays between the logo's "S" strokes,
  half an element wide, each ended by such a half circle, got a valence-5 point and a
  degenerate block, 93 % of the quads in blocks, worst 0.39, 11 s; squared, all blocks,
  worst 0.55, 1 s; a 10 x 0.5 strip with round ends meshed at size 1: worst 0.42 as
  curves, 1.0 squared).  Larger ones stay as their curves are (a rib 1.7 sizes wide:
  worst 0.71 squared, 0.83 as curves);
- a concave half circle of a radius under SLOT_END sizes (the end of a keyway or a slot
  cut into the part, turning by more than ROUND_SWEEP) is one concave corner too, chained
  with the turns beside it however long it is: read as a curve it needs two valence-5
  points within an element of each other, which the background cannot place (a
  crankshaft web's keyway: a block turned back by 104°, 13 % of its quads unstructured);
  as a corner (a slit's end) it needs none.
- a concave half circle of a radius from SLOT_END up to WIDE_SLOT_END sizes (a wider
  slot's end, turning by more than ROUND_SWEEP, up to SLOT_SWEEP, between smooth joins)
  is two concave corners, each in the middle of its half, as a small round hole's square
  has: read as a curve it needs two valence-5 points an element or so apart, which the
  background cannot place either where other features crowd it (Prusa i3 power-panic
  face at diameter/100: no line reached six slots of radius 1.05 sizes, 69 % of the
  quads in blocks, 25 s); as a slot with square ends it needs none.  From
  WIDE_SLOT_END sizes on the field places them well (corpus control_arm's 145° arcs of
  2 sizes read as corners: a worst quad of 0.77 against 0.91).
- a slot hole shorter than SMALL_SLOT sizes end to end (_is_small_slot) is a rectangle:
  each end two corners, as a wider slot's, whatever its radius, as a small round hole
  is a square (input.small_holes).
A lone corner is never changed, nor a flat chain whose corners are each flat already, nor
a chain of turns longer than MAX_SPAN sizes (a curve stored as a polyline: see below; one
fillet's length is bounded by its radius rule), so a part with no such features is read
exactly as before.

A joint that turns by less than SMOOTH_TURN is a smooth join wherever it is: a circle
or fillet stored as a polyline (a DXF or mesh-derived export, 2° a joint) would otherwise
make every one of its vertices a vertex of the partition, a place a mesh node must sit,
and a hundred vertices 0.3 sizes apart along a hole's rim leave no segment counts that
make opposite block sides equal (pulley_protection's face had a quarter of its quads in
blocks).  Such a joint is flat, as a step's are, unless it is a concave feature's corner
(a fillet stored as a polyline still gets its corner).  The mesh then cuts the joint by
under an element times sin(SMOOTH_TURN / 2) / 2.

The field (background.py), its corner streamlines and the partition's vertices read the
boundary through these features, so they agree on where the corners are.  The quality
measure does not: DESIGN.md counts a boundary node as irregular by its own interior
angle, so a small fillet's corner node, with three quads where the boundary is smooth,
is one irregular vertex (as the valence-5 point a fillet read as a curve needs would be).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .corners import interior_angle, is_corner, nearest_quarters, tie_shortfall
from .small_holes import field_direction, is_quartered

FEATURE = 0.5  # element sizes: turns closer together than this are one feature
ROUND = 2.5  # element sizes: a concave fillet of a smaller radius is read as a corner ...
ROUND_SWEEP = math.radians(135)  # ... up to this turn (a slot's end: SLOT_END, WIDE_SLOT_END)
SLOT_END = 1.0  # element sizes: ... unless its radius is under this (a narrow slot's end)
SLOT_SWEEP = math.radians(200)  # ... turning at most this
WIDE_SLOT_END = 1.5  # element sizes: from SLOT_END up to this radius, two corners
SMALL_SLOT = 1.5  # element sizes: a slot shorter than this end to end is a rectangle
CONVEX_ROUND = 1.0  # element sizes: so is a convex fillet of a smaller radius
MAX_SPAN = 3.0  # element sizes: a longer chain of turns is no feature
JOINT_TOL = 1e-9  # a middle this close (in curve parameter) to a joint is that joint,
JOINT_GAP = 1e-3  # ... and so is one this close in element sizes (a cut there would leave
#                   gmsh a curve too short to draw)
# A joint turning less is a smooth join.  Not a round number of degrees: a regular polygon
# of 24, 30 or 36 sides turns by 15°, 12° or 10°, and which side of the rule such a
# polyline falls on must not hang on round-off.
SMOOTH_TURN = math.radians(12.5)
CONVEX_MIN = math.radians(22.5)  # a convex feature this sharp or blunter is one corner
CONVEX_END = 0.75  # element sizes: a sharper convex arc of a smaller radius is two corners
SMALL_SHAPED_HOLE = 3.0  # element sizes: a hole of any shape this small is a square,
SMALL_SMOOTH_HOLE = 1.0  # ... one with no corner this small
HOLE_SAMPLES = 32  # points per curve where a small hole's square corners are sought
SUPPORT_TIE = 1e-6  # element sizes: points this close to the farthest one tie with it


def is_smooth_join(angle: float) -> bool:
    """Whether a joint of this interior angle turns by less than SMOOTH_TURN (a tangent
    joint included): the layout reads it as no corner, and slides run over it."""
    return abs(math.pi - angle) < SMOOTH_TURN


@dataclass(frozen=True)
class Feature:
    """A stretch of one loop read as one joint: a corner (angle) or flat (angle None)."""

    loop: int
    joints: tuple  # segments whose starting joint is in the stretch (a member, or smooth),
    #                but the pivot: no corner, no place a mesh node must sit
    start: float  # arc length along the loop where the stretch starts
    end: float  # ... and ends (may exceed the loop's length: the stretch wraps)
    pivot: float  # arc length of its middle: where it turns (a concave one's corner)
    pivot_segment: int  # the curve holding the pivot
    pivot_param: float  # its parameter there (0.0: the joint at the curve's start)
    angle: float | None  # interior angle of the whole stretch; None: flat
    tangent_in: np.ndarray  # the tangent arriving at the stretch
    tangent_out: np.ndarray  # the tangent leaving it
    # > 0: a wavy loop (_wavy_loop), whose tangent is its mean over this arc length either
    # side of each point
    window: float = 0.0


def loop_offsets(loop) -> np.ndarray:
    """Arc length at the start of each curve of a loop."""
    return np.concatenate([[0.0], np.cumsum([c.length for c in loop])])


def _turns(loop) -> list:
    """(arc length, signed turn, segment, kind, start, end) of each corner and each short
    curve's whole turn, in loop order; the turn is positive to the left."""
    offsets = loop_offsets(loop)
    out = []
    for si, curve in enumerate(loop):
        angle = interior_angle(loop[si - 1], curve)
        if is_corner(angle):
            out.append((offsets[si], math.pi - angle, si, "joint", offsets[si], offsets[si]))
        sweep = getattr(curve, "sweep", 0.0)
        if sweep:
            out.append((offsets[si] + 0.5 * curve.length, sweep, si, "curve",
                        offsets[si], offsets[si + 1]))
    return out


def boundary_features(domain, size: float) -> list:
    """The features of every loop at element size ``size`` (see the module docstring).

    Turns chain into one feature while each is less than FEATURE sizes from the next, a
    rule that reads a loop the same both ways round (a mirrored copy runs the other way);
    a chain longer than MAX_SPAN sizes (a curve stored as a polyline) is no feature, but
    its joints under SMOOTH_TURN are smooth joins (_smooth_joints)."""
    out = []
    for li, loop in enumerate(domain.loops):
        if is_quartered(loop):  # a small round hole, squared (small_holes.py decides)
            out.extend(_square_corners(li, loop))
            continue
        small = _small_hole_corners(domain, li, size)
        if small:
            out.extend(small)
            continue
        if len(loop) < 2:
            continue  # a lone circle: no corner to read
        features = _loop_features(li, loop, size)
        out.extend(features + _smooth_joints(li, loop, features))
    return out


def _smooth_joints(li, loop, features) -> list:
    """A flat feature at each joint turning less than SMOOTH_TURN that no feature holds
    already (as a member, or as its corner)."""
    held = {si for f in features for si in f.joints}
    held |= {f.pivot_segment for f in features if f.pivot_param == 0.0}
    offsets = loop_offsets(loop)
    out = []
    for si, curve in enumerate(loop):
        angle = interior_angle(loop[si - 1], curve)
        if si in held or not is_corner(angle) or not is_smooth_join(angle):
            continue
        at = float(offsets[si])
        out.append(Feature(li, (si,), at, at, at, si, 0.0, None,
                           np.asarray(loop[si - 1].tangent(1.0), float),
                           np.asarray(curve.tangent(0.0), float)))
    return out


def _loop_features(li, loop, size) -> list:
    """One loop's features (see boundary_features), smooth joints aside."""
    if _is_small_slot(li, loop, size):
        return [f for si, arc in enumerate(loop) if getattr(arc, "sweep", 0.0)
                for f in _end_corners(li, loop, si)]
    features = _chained_features(li, loop, size)
    return features + _two_corner_ends(li, loop, features, size)


def _is_small_slot(li, loop, size) -> bool:
    """Whether a hole is a slot shorter than SMALL_SLOT sizes end to end: lines and two
    round ends (_round_end, up to WIDE_SLOT_END), every join smooth.  It is read as a
    small round hole is, a rectangle at the mesh's scale (each end two corners, as
    _two_corner_ends has them).  Read by the other rules (each narrow end one corner,
    chained with the sides when they are short) a slot of one to 1.3 sizes left a loop
    the layout could not reach: a plate with one slot 8 x 2.8 mm at its 6.5 mm default
    size had no block at all (the quads covered the slot).  Longer slots are slits
    there, with two irregular vertices fewer (corpus bracket_plate's five slots of 2.8
    sizes: 16 irregular vertices, 26 as rectangles, the same worst quad)."""
    ends = [c for c in loop if getattr(c, "sweep", 0.0)]
    if li == 0 or len(ends) != 2 or len(loop) > 4 \
            or not all(_round_end(c, size, 0.0, WIDE_SLOT_END) for c in ends):
        return False
    if not all(is_smooth_join(interior_angle(loop[k - 1], loop[k])) for k in range(len(loop))):
        return False
    a, b = ends
    length = float(np.hypot(*(a.center - b.center))) + a.radius + b.radius
    return _sizes(length, size) < SMALL_SLOT


def _chained_features(li, loop, size) -> list:
    """The features chained from the loop's turns, chamfers included."""
    out = []
    total = float(loop_offsets(loop)[-1])
    turns = [t for t in _turns(loop) if t[3] == "joint" or _sizes(t[5] - t[4], size) < FEATURE
             or (_sizes(loop[t[2]].radius, size) < ROUND
                 and -ROUND_SWEEP <= _turn(t[1]) < 0.0)
             or _slot_end(loop, t, size)
             or (_sizes(loop[t[2]].radius, size) < CONVEX_ROUND
                 and 0.0 < _turn(t[1]) <= math.pi - CONVEX_MIN)]
    if not turns:
        return out
    lengths = [(turns[(k + 1) % len(turns)][4] - t[5]) % total for k, t in enumerate(turns)]
    # A fillet an element long or more is a feature on its own: the corner beside it
    # is one of the part's, not a detail of the fillet.
    # Not from the other half of a fillet stored as two arcs, though (a crank web's
    # rounded slot corner at diameter/100: two 233° corners an element apart, each
    # with its own streamlines, beside the singular point the fillet put there).
    long = [_sizes(t[5] - t[4], size) >= 1.0 and not _slot_end(loop, t, size) for t in turns]
    apart = [(long[k] or long[(k + 1) % len(turns)])
             and not _split_fillet(loop, t, turns[(k + 1) % len(turns)])
             for k, t in enumerate(turns)]  # a chain ends after turn k whatever the gap
    gaps = [FEATURE if cut else _sizes(gap, size) for cut, gap in zip(apart, lengths)]
    if len(turns) > 1 and max(gaps) < FEATURE:
        return _wavy_loop(li, loop, size)  # the whole loop is one chain
    # Any chain boundary would do (the chains are the same from each); the widest gap,
    # in lengths, keeps the features in the order they always came in.
    first = (int(np.argmax([FEATURE * size if cut else gap
                            for cut, gap in zip(apart, lengths)])) + 1) % len(turns)
    chains, chain = [], []
    for k in range(first, first + len(turns)):
        chain.append(turns[k % len(turns)])
        if gaps[k % len(turns)] >= FEATURE:
            chains.append(chain)
            chain = []
    for chain in chains:
        feature = _feature(li, loop, chain, total, size)
        if feature is not None:
            out.append(feature)
    return out + _chamfers(li, loop, out, size, total, turns)


def _two_corner_ends(li, loop, features, size) -> list:
    """Two corners (_end_corners) for each wider slot's round end and each narrow rib's
    (see the module docstring): a concave arc of a radius from SLOT_END up to
    WIDE_SLOT_END sizes turning by more than ROUND_SWEEP, up to SLOT_SWEEP, or a convex
    one (_convex_end), whose joints are smooth and held
    by no other feature.  Held are the joints (a segment's starting one) in a feature or
    at its pivot, and the curves a pivot lies within: both end joints are asked, so a
    mirrored copy asks the same."""
    held = {si for f in features for si in f.joints} \
        | {f.pivot_segment for f in features if f.pivot_param == 0.0}
    within = {f.pivot_segment for f in features if f.pivot_param != 0.0}
    offsets = loop_offsets(loop)
    out = []
    for si, arc in enumerate(loop):
        after = (si + 1) % len(loop)
        if {si, after} & held or si in within \
                or not (_round_end(arc, size, SLOT_END, WIDE_SLOT_END)
                        or _convex_end(arc, size)):
            continue
        joints = (interior_angle(loop[si - 1], arc), interior_angle(arc, loop[after]))
        if any(is_corner(a) and not is_smooth_join(a) for a in joints):
            continue
        out += _end_corners(li, loop, si, offsets)
    return out


def _end_corners(li, loop, si, offsets=None) -> list:
    """A slot's or a rib's round end (curve ``si``) as two corners, each holding half the
    arc and sitting in its middle, a quarter of the arc from either end: the same places
    whichever way the loop runs."""
    offsets = loop_offsets(loop) if offsets is None else offsets
    arc = loop[si]
    start, end = float(offsets[si]), float(offsets[si + 1])
    middle = 0.5 * (start + end)
    return [Feature(li, (), lo, hi, 0.5 * (lo + hi), si, param, math.pi - 0.5 * arc.sweep,
                    np.asarray(arc.tangent(param - 0.25), float),
                    np.asarray(arc.tangent(param + 0.25), float))
            for lo, hi, param in ((start, middle, 0.25), (middle, end, 0.75))]


def _chamfers(li, loop, features, size, total, turns) -> list:
    """Chamfers read as one corner each where the loop's ties leave its turn ambiguous.

    A rectangle with two corners chamfered an element wide has four 135° joints, each a
    tie between one quad and two; the loop's corners, rounded the even way, are two, and
    any two of the four ties could make up the missing quarters (input.corners.odd_ties
    leaves such a loop alone: no rule picks which).  Read that way the part had two
    corners and no singular point, and all of it got unstructured quads (fsr-dance-pad's
    breadboard platform, face 118, at diameter/100; at the default size the chamfers are
    under FEATURE sizes and already features).  Where the ties pair up into chamfers,
    each a straight curve under MAX_SPAN sizes with a tie at either end turning the same
    way, and the pairs are exactly as many as the quarters missing, each chamfer is one
    corner in its middle: the same in a mirrored copy, no pose picks an end.
    ``turns``: the loop's turns as _loop_features kept them (every joint among them)."""
    short, helping = tie_shortfall(li, loop)
    if not helping or len(helping) == abs(short):
        return []
    held = {si for f in features for si in f.joints} | {f.pivot_segment for f in features}
    ties = set(helping)
    pairs = [k for k in sorted(ties) if (k + 1) % len(loop) in ties
             and getattr(loop[k], "sweep", 0.0) == 0.0 and loop[k].length < MAX_SPAN * size
             and not {k, (k + 1) % len(loop)} & held]
    used = [j for k in pairs for j in (k, (k + 1) % len(loop))]
    if len(pairs) != abs(short) or len(set(used)) != len(used) or set(used) != ties:
        return []
    joints = {t[2]: t for t in turns if t[3] == "joint"}
    out = []
    for k in pairs:
        feature = _feature(li, loop, [joints[k], joints[(k + 1) % len(loop)]], total, size)
        if feature is not None:
            out.append(feature)
    return out


WAVY_TURN = math.radians(30)  # most the mean tangent of a wavy loop turns in one size
MEAN_SHIFTS = 2  # chords averaged either side of the middle one (mean_tangents)
WAVY_SAMPLES = 8  # points per curve of the polyline the mean tangent is taken on


def _wavy_loop(li, loop, size) -> list:
    """A loop that is one chain of turns all round (a knurled ring, a serrated hole, a
    gear at a size above its teeth) and whose mean tangent over an element either side
    turns gently (less than WAVY_TURN in one size): one flat feature over the whole loop,
    every joint flat, the field following the mean tangent.  Read as it is, every joint
    was a vertex of the partition and every tooth a corner with its own streamlines
    (held-out 0078, a knurled ring of 1344 arcs of under a quarter of an element: 2605
    blocks, and no segment counts within 200 s); at the element's scale it is a circle.
    [] (read as it is) where the mean tangent turns sharply: the loop has corners at
    the element's scale too."""
    total = float(loop_offsets(loop)[-1])
    if total < MAX_SPAN * size or all(
            is_smooth_join(interior_angle(loop[k - 1], loop[k])) for k in range(len(loop))):
        return []  # small, or a curve stored as a polyline (smooth joins: _smooth_joints)
    s = np.arange(0.0, total, 0.25 * size)
    tangents = mean_tangents(loop, s, size)
    angles = np.angle(tangents[:, 0] + 1j * tangents[:, 1])
    turn = np.angle(np.exp(1j * (np.roll(angles, -4) - angles)))  # over one size
    if np.abs(turn).max() >= WAVY_TURN:
        return []
    return [Feature(li, tuple(range(len(loop))), 0.0, total, 0.0, 0, 0.0, None,
                    np.asarray(loop[-1].tangent(1.0), float),
                    np.asarray(loop[0].tangent(0.0), float), window=float(size))]


def mean_tangents(loop, s, window: float) -> np.ndarray:
    """Unit tangent of a closed loop at arc lengths ``s``, averaged over ``window`` either
    side: the chord between the two points that far along (the mean of the unit tangent
    is that chord over its arc length), itself averaged over MEAN_SHIFTS shifts of half a
    window either way (one window's chord swung by 30° with the phase of a knurl's teeth
    at its ends; the average, by 4°).  On a polyline of the loop sampled at fixed
    curve parameters, which a turned or mirrored copy shares."""
    t = np.linspace(0.0, 1.0, WAVY_SAMPLES + 1)[:-1]
    points = np.concatenate([curve.point(t) for curve in loop])
    closed = np.vstack([points, points[:1]])
    along = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(closed, axis=0).T))])
    total = along[-1]

    def at(x):
        x = np.mod(x, total)
        return np.column_stack([np.interp(x, along, closed[:, 0]),
                                np.interp(x, along, closed[:, 1])])

    scale = total / float(loop_offsets(loop)[-1])  # the polyline is a little shorter
    chord = 0.0
    for k in range(-MEAN_SHIFTS, MEAN_SHIFTS + 1):
        middle = (np.asarray(s, dtype=float) + k * window / MEAN_SHIFTS) * scale
        chord = chord + at(middle + window * scale) - at(middle - window * scale)
    return chord / np.hypot(*chord.T)[:, None]


def _split_fillet(loop, first, second) -> bool:
    """Whether consecutive turns lie inside one fillet stored as two arcs: concave arcs
    one after the other, joined smoothly (a kink under SMOOTH_TURN, itself a turn or
    not), turning by at most ROUND_SWEEP together."""
    n = len(loop)
    # A curve's turn is numbered by its segment, a joint's by the segment it starts.
    if first[3] == "curve" and second[2] == (first[2] + 1) % n:
        arcs = (first[2], second[2])  # the next arc, or the joint that starts it
    elif first[3] == "joint" and second[3] == "curve" and first[2] == second[2]:
        arcs = ((second[2] - 1) % n, second[2])  # the joint that ends the arc before
    else:
        return False
    a, b = loop[arcs[0]], loop[arcs[1]]
    sweep_a, sweep_b = getattr(a, "sweep", 0.0), getattr(b, "sweep", 0.0)
    return sweep_a < 0.0 and sweep_b < 0.0 and -(sweep_a + sweep_b) <= ROUND_SWEEP \
        and is_smooth_join(interior_angle(a, b))


def _slot_end(loop, turn, size) -> bool:
    """Whether a turn is a narrow slot's round end: a concave arc of a radius under
    SLOT_END sizes turning by more than ROUND_SWEEP, up to SLOT_SWEEP."""
    return turn[3] == "curve" and _round_end(loop[turn[2]], size, 0.0, SLOT_END)


def _convex_end(curve, size) -> bool:
    """Whether a curve is a rib's round end under CONVEX_END sizes in radius: a convex
    arc turning by more than pi - CONVEX_MIN, up to SLOT_SWEEP."""
    sweep = getattr(curve, "sweep", 0.0)
    return sweep > 0.0 and _sizes(curve.radius, size) < CONVEX_END \
        and math.pi - CONVEX_MIN < _turn(sweep) <= SLOT_SWEEP


def _round_end(curve, size, smallest: float, largest: float) -> bool:
    """Whether a curve is a slot's round end of a radius from ``smallest`` up to
    ``largest`` sizes: a concave arc turning by more than ROUND_SWEEP, up to SLOT_SWEEP."""
    sweep = getattr(curve, "sweep", 0.0)
    return bool(sweep) and smallest <= _sizes(curve.radius, size) < largest \
        and -SLOT_SWEEP <= _turn(sweep) < -ROUND_SWEEP


RULE_DIGITS = 9  # sizes and radians are compared with the rules' bounds at this rounding


def _sizes(length: float, size: float) -> float:
    """A length in element sizes, rounded well above round-off: a part drawn in round
    numbers puts fillets exactly on the rules' bounds (a 135° fillet against
    ROUND_SWEEP), where a moved copy's last bit decided (fsr-dance-pad
    breadboard-platform face 19 at diameter/100: four fillets corners in one copy and
    curves in the other, 92 blocks against 85)."""
    return round(length / size, RULE_DIGITS)


def _turn(angle: float) -> float:
    """A turn in radians, rounded as _sizes is."""
    return round(angle, RULE_DIGITS)


def _square_corners(li, loop) -> list:
    """A quartered hole's four concave corners, one at each quarter arc's middle; the
    smooth joints between the arcs (where the square's sides touch the circle) are flat."""
    offsets = loop_offsets(loop)
    return [Feature(li, (k,), float(offsets[k]), float(offsets[k + 1]),
                    float(0.5 * (offsets[k] + offsets[k + 1])), k, 0.5, 1.5 * math.pi,
                    np.asarray(arc.tangent(0.0), float), np.asarray(arc.tangent(1.0), float))
            for k, arc in enumerate(loop)]


def _small_hole_corners(domain, li: int, size: float) -> list:
    """A hole of any shape smaller than SMALL_SHAPED_HOLE sizes across (a logo's letter,
    a short slot, a round hole stored as several curves), read as a square, as
    small_holes reads a round one: four concave corners where the hole reaches farthest
    along the square's diagonals (turned to the field the other loops impose), each
    holding a quarter of the rim, every other joint flat.  Read as it is, each of its
    corners sent streamlines and the field round it had singular points an element
    apart: a part with five such letters got no block at all.  A hole with no corner
    (a short slot, an oval stored as arcs) is squared only below SMALL_SMOOTH_HOLE: the
    field follows it well from there (held-out 0095's bolt holes, 14 arcs each, squared
    at 1.9 sizes, left 5 % of its quads out of blocks; as they are, none; at 0.7 sizes,
    as they are, 38 %).  [] where the rule does not apply (an outer loop, a larger
    hole, a hole whose farthest points do not come in the diagonals' order round it)."""
    loop = domain.loops[li]
    if li == 0 or len(loop) < 2:
        return []
    t = np.linspace(0.0, 1.0, HOLE_SAMPLES + 1)[:-1]
    offsets = loop_offsets(loop)
    points = np.vstack([np.atleast_2d(c.point(t)) for c in loop])
    along = np.concatenate([offsets[si] + t * c.length for si, c in enumerate(loop)])
    # Its diameter, as its widest extent over 64 directions (within 0.03 %; a hole
    # stored as a fine polyline has too many points for all their pairs).
    angles = np.arange(64) * (math.pi / 64)
    reach = points @ np.array([np.cos(angles), np.sin(angles)])
    joints = [interior_angle(loop[si - 1], c) for si, c in enumerate(loop)]
    smooth = all(not is_corner(a) or is_smooth_join(a) for a in joints)
    limit = SMALL_SMOOTH_HOLE if smooth else SMALL_SHAPED_HOLE
    if (reach.max(axis=0) - reach.min(axis=0)).max() >= limit * size:
        return []
    total = float(offsets[-1])
    weights = np.repeat([c.length for c in loop], HOLE_SAMPLES)
    centre = weights @ points / weights.sum()
    theta = field_direction(domain, li, centre)
    pivots = []
    for k in range(4):
        a = theta + 0.25 * math.pi + 0.5 * math.pi * k
        reach = (points - centre) @ np.array([math.cos(a), math.sin(a)])
        tied = reach >= reach.max() - SUPPORT_TIE * size
        pivots.append(_farthest_run(domain, li, points, along, tied, total, centre, size))
    order = np.argsort(pivots)
    steps = {int(order[(j + 1) % 4] - order[j]) % 4 for j in range(4)}
    if steps not in ({1}, {3}) or min(np.diff(np.sort(pivots))) <= SUPPORT_TIE * size:
        return []  # the farthest points do not go round the hole in the diagonals' order
    pivots = [pivots[j] for j in order]
    corners = [_at(loop, offsets, s, size) for s in pivots]
    out = []
    for j in range(4):
        before, here, after = pivots[j - 1], pivots[j], pivots[(j + 1) % 4]
        start = (before + 0.5 * ((here - before) % total)) % total
        end = start + 0.5 * ((here - before) % total) + 0.5 * ((after - here) % total)
        seg, param = corners[j]
        chord_in = _point(loop, offsets, here) - _point(loop, offsets, before)
        chord_out = _point(loop, offsets, after) - _point(loop, offsets, here)
        joints = tuple(si for si, at in enumerate(offsets[:-1])
                       if _within(at, start, end, total)
                       and not (param == 0.0 and si == seg))
        out.append(Feature(li, joints, float(start), float(end), float(here), seg,
                           float(param), 1.5 * math.pi, _axis(chord_in, theta),
                           _axis(chord_out, theta)))
    return out


def _farthest_run(domain, li, points, along, tied, total, centre, size) -> float:
    """Arc length of the corner among the points that reach farthest along a diagonal
    (``tied``): the middle of a run of them (a side square to the diagonal), never a
    point between two runs (between a plus sign's two arm tips lies its inner corner, a
    corner of the part's material that read as a hole's corner folded the quads round
    it).  Of several runs, the one farthest from the hole's centre, then the nearest to
    the part's other loops: what a turned or mirrored copy picks alike."""
    n = len(tied)
    if tied.all():
        return 0.0
    start = int(np.argmin(tied))  # a point of no run: runs are read from there on
    runs, run = [], []
    for i in range(start, start + n + 1):
        if tied[i % n]:
            run.append(i % n)
        elif run:
            runs.append(run)
            run = []
    def middle(run):
        span = (along[run[-1]] - along[run[0]]) % total
        return (along[run[0]] + 0.5 * span) % total, points[run[len(run) // 2]]

    if len(runs) == 1:
        return float(middle(runs[0])[0])
    others = np.vstack([np.atleast_2d(c.point(np.linspace(0.0, 1.0, HOLE_SAMPLES)))
                        for lj, loop in enumerate(domain.loops) if lj != li for c in loop])

    def key(run):
        xy = middle(run)[1]
        nearest = np.hypot(*(others - xy).T).min()
        return (-round(float(np.hypot(*(xy - centre))) / size, 6),
                round(float(nearest) / size, 6))

    return float(middle(min(runs, key=key))[0])


def _within(at: float, start: float, end: float, total: float) -> bool:
    """Whether arc length ``at`` lies on the stretch from ``start`` to ``end`` (end >=
    start, wrapping round a loop of length ``total``), its ends included within JOINT_TOL
    of the loop.  Measured from the start modulo the loop, an end joint came out an ulp
    past the stretch or not as the loop happened to start: held-out Prusa MINI
    minda-holder f103 had a 270° corner in its notch's feature and, mirrored, not in
    it (a corner source more, 57 blocks against 58)."""
    into = (at - start) % total
    tol = JOINT_TOL * total
    return into <= end - start + tol or into >= total - tol


def _located(loop, offsets, s: float) -> tuple:
    """(segment, parameter) at arc length s along the loop."""
    seg = int(np.clip(np.searchsorted(offsets, s, side="right") - 1, 0, len(loop) - 1))
    return seg, (s - offsets[seg]) / loop[seg].length


def _at(loop, offsets, s: float, size: float) -> tuple:
    """(segment, parameter) at arc length s, on the joint if within JOINT_GAP of one."""
    seg, param = _located(loop, offsets, s)
    near = max(JOINT_TOL, JOINT_GAP * size / loop[seg].length)
    if param >= 1.0 - near:
        return (seg + 1) % len(loop), 0.0
    return seg, (0.0 if param <= near else float(param))


def _point(loop, offsets, s: float) -> np.ndarray:
    seg, param = _located(loop, offsets, s)
    return np.asarray(loop[seg].point(param), float)


def _axis(chord, theta: float) -> np.ndarray:
    """The direction of the square's sides (theta + k 90°) nearest to a chord's."""
    k = round((math.atan2(chord[1], chord[0]) - theta) / (0.5 * math.pi))
    a = theta + 0.5 * math.pi * k
    return np.array([math.cos(a), math.sin(a)])


def _feature(li, loop, group, total, size) -> Feature | None:
    if len(group) == 1 and group[0][3] == "joint":
        return None  # a lone corner: as it is
    span = (group[-1][5] - group[0][4]) % total
    if len(group) > 1 and span > MAX_SPAN * size:
        return None  # a long chain of turns: a curve stored as a polyline
    turn = sum(t[1] for t in group)
    angle = math.pi - turn
    quarters = nearest_quarters(angle) if is_corner(angle) else 2
    if angle < CONVEX_MIN:
        return None  # a narrow slot's round end: its curves as they are
    if quarters == 2 and all(t[3] == "curve" or nearest_quarters(math.pi - t[1]) == 2
                             for t in group):
        return None  # flat, and so is each of its corners: nothing to change
    first, last = group[0], group[-1]
    start = first[4]
    end = last[5] if last[5] >= start else last[5] + total
    offsets = loop_offsets(loop)
    members = {t[2] for t in group if t[3] == "joint"}
    inside = [si for si, at in enumerate(offsets[:-1]) if _within(at, start, end, total)
              and (si in members or not is_corner(interior_angle(loop[si - 1], loop[si])))]
    t_in = loop[first[2] - 1].tangent(1.0) if first[3] == "joint" \
        else loop[first[2]].tangent(0.0)
    t_out = loop[last[2]].tangent(0.0) if last[3] == "joint" else loop[last[2]].tangent(1.0)
    # The stretch turns in its middle, the same place whichever way the loop runs (a
    # mirrored copy runs it the other way); a concave one's corner sits there, on a joint
    # if the middle is one.
    middle = (start + 0.5 * (end - start)) % total
    seg, param = _at(loop, offsets, middle, size)
    flat = quarters == 2
    joints = tuple(si for si in inside if flat or not (param == 0.0 and si == seg))
    return Feature(li, joints, start, end, middle, seg, float(param), None if flat else angle,
                   np.asarray(t_in, float), np.asarray(t_out, float))
