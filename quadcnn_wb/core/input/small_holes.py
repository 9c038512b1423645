"""Round holes of a few elements across, read as squares at the mesh's scale.

A bolt hole of an element or two across cannot be followed by the mesh, and read as a
circle it bends the cross field round it into four valence-3 singular points, a ring of
separatrices and slivers a fraction of an element wide (nist_ctc04_plate's 33 holes at
the default size: half its faces no blocks).  A grid of quads passes such a hole as it
would a square one: the hole takes the place of a few quads, and its four corners send
the streamlines of any concave corner along the grid.  So a full circle of a diameter
under SMALL_HOLE sizes becomes four quarter arcs, each read as one concave corner at its
middle (input.features), turned to the field the surrounding boundary imposes there: the
mean of its tangents' quarter-turn directions, weighted by the inverse fourth power of
the distance (the field near a hole follows the nearest boundary, and a weighted mean has
no ties for round-off to break, where a nearest point may).  Not a hole in a boss whose
wall is thinner than an element: its rings of quads follow the boss.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .curves import Arc
from .pose import canonical_pose

SMALL_HOLE = 3.0  # element sizes: a round hole of a smaller diameter is read as a square
# ... and one under this, where the layout reading it round leaves free faces near it
# (pipeline.mesh_domain): held-out nist_ctc_05 f164 at diameter/100, 10 bolt holes of 3.4
# sizes, two of whose rings of valence-5 points closed lenses and a six-cornered face.
SQUARED_RESCUE = 4.0
SAMPLES = 64  # points per curve for the surrounding boundary's direction
CONCENTRIC = 1e-3  # radii: arcs whose centres are this close are concentric
CANCELLED = 1e-6  # a weighted mean direction this short (of the weights) is none


def is_quartered(loop) -> bool:
    """Whether a loop is the four quarter arcs of one circle that squared_holes made (input
    healing merges the arcs of one circle, so no input loop is one)."""
    if len(loop) != 4 or not all(isinstance(c, Arc) for c in loop):
        return False
    first = loop[0]
    return all(abs(abs(c.sweep) - 0.5 * math.pi) < 1e-9 and c.radius == first.radius
               and np.array_equal(c.center, first.center) for c in loop)


def squared_holes(domain, size: float, below: float = SMALL_HOLE):
    """The domain with every round hole of a diameter under ``below`` sizes made of four
    quarter arcs whose middles are the square's corners."""
    loops = list(domain.loops)
    changed = False
    for li in range(1, len(loops)):
        loop = loops[li]
        if len(loop) != 1 or not isinstance(loop[0], Arc) or not loop[0].is_full:
            continue
        circle = loop[0]
        if 2.0 * circle.radius >= below * size or _in_thin_boss(domain, li, circle, size):
            continue
        theta = field_direction(domain, li, circle.center)
        loops[li] = _quarters(circle, theta)
        changed = True
    return dataclasses.replace(domain, loops=tuple(loops)) if changed else domain


def _in_thin_boss(domain, hole: int, circle: Arc, size: float) -> bool:
    """Whether an arc of another loop round the same centre lies within a size of the
    hole's rim: a boss's wall thinner than an element, which its rings of quads follow
    (squared, engine_top's bosses sent corner streamlines into a 0.5-element wall)."""
    tol = CONCENTRIC * circle.radius
    return any(isinstance(c, Arc) and np.hypot(*(c.center - circle.center)) <= tol
               and c.radius < circle.radius + size
               for li, loop in enumerate(domain.loops) if li != hole for c in loop)


def field_direction(domain, hole: int, centre) -> float:
    """The cross field's direction (mod 90°) that the other loops impose at ``centre``;
    where they cancel (a hole at the middle of a symmetric part, which any turn of the
    square fits as well), the direction of the part's canonical pose, so that a turned
    or mirrored copy turns its square alike rather than as round-off has it."""
    loops, points, lengths, turns = _boundary_samples(domain)
    others = loops != hole
    distance = np.hypot(*np.moveaxis(points[others] - centre, -1, 0))
    weight = lengths[others, None] / SAMPLES / np.maximum(distance, 1e-300) ** 4
    # Summed curve by curve, in the loops' order, as a loop over the curves would.
    total, weights = 0j, 0.0
    for turn, weight_sum in zip(np.sum(weight * turns[others], axis=1),
                                np.sum(weight, axis=1)):
        total += turn
        weights += float(weight_sum)
    if abs(total) <= CANCELLED * weights:
        axis = canonical_pose(domain).matrix[0]
        return math.atan2(axis[1], axis[0])
    return float(np.angle(total) / 4.0)


def _boundary_samples(domain) -> tuple:
    """(loop of each curve, its SAMPLES points, its length, exp(4i tangent angle) at
    them), sampled once per domain: every small hole of a part with hundreds of curves
    asks (held-out 0095: 0.35 s a background, three times a run, when each sampled the
    curves again)."""
    cached = domain.__dict__.get("_field_samples")
    if cached is None:
        t = (np.arange(SAMPLES) + 0.5) / SAMPLES
        curves = [(li, curve) for li, loop in enumerate(domain.loops) for curve in loop]
        points = np.array([np.atleast_2d(curve.point(t)) for _, curve in curves])
        tangents = np.array([np.atleast_2d(curve.tangent(t)) for _, curve in curves])
        turns = np.exp(4j * np.arctan2(tangents[..., 1], tangents[..., 0]))
        cached = (np.array([li for li, _ in curves]), points,
                  np.array([curve.length for _, curve in curves]), turns)
        domain.__dict__["_field_samples"] = cached
    return cached


def _quarters(circle: Arc, theta: float) -> tuple:
    """Four quarter arcs, running as the circle runs, joined where the square's sides
    are tangent to the circle (theta + k 90°), so their middles are its corners."""
    step = math.copysign(0.5 * math.pi, circle.sweep)
    starts = [theta + k * step for k in range(4)]
    joints = [circle.center + circle.radius * np.array([math.cos(a), math.sin(a)])
              for a in starts]
    return tuple(Arc(circle.center, circle.radius, starts[k], step, joints[k],
                     joints[(k + 1) % 4]) for k in range(4))
