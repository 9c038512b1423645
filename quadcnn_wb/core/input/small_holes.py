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


def squared_holes(domain, size: float):
    """The domain with every round hole of a diameter under SMALL_HOLE sizes made of four
    quarter arcs whose middles are the square's corners."""
    loops = list(domain.loops)
    changed = False
    for li in range(1, len(loops)):
        loop = loops[li]
        if len(loop) != 1 or not isinstance(loop[0], Arc) or not loop[0].is_full:
            continue
        circle = loop[0]
        if 2.0 * circle.radius >= SMALL_HOLE * size or _in_thin_boss(domain, li, circle, size):
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
    total, weights = 0j, 0.0
    t = (np.arange(SAMPLES) + 0.5) / SAMPLES
    for li, loop in enumerate(domain.loops):
        if li == hole:
            continue
        for curve in loop:
            points = np.atleast_2d(curve.point(t))
            tangents = np.atleast_2d(curve.tangent(t))
            distance = np.hypot(*(points - centre).T)
            weight = curve.length / SAMPLES / np.maximum(distance, 1e-300) ** 4
            alpha = np.arctan2(tangents[:, 1], tangents[:, 0])
            total += np.sum(weight * np.exp(4j * alpha))
            weights += float(np.sum(weight))
    if abs(total) <= CANCELLED * weights:
        axis = canonical_pose(domain).matrix[0]
        return math.atan2(axis[1], axis[0])
    return float(np.angle(total) / 4.0)


def _quarters(circle: Arc, theta: float) -> tuple:
    """Four quarter arcs, running as the circle runs, joined where the square's sides
    are tangent to the circle (theta + k 90°), so their middles are its corners."""
    step = math.copysign(0.5 * math.pi, circle.sweep)
    starts = [theta + k * step for k in range(4)]
    joints = [circle.center + circle.radius * np.array([math.cos(a), math.sin(a)])
              for a in starts]
    return tuple(Arc(circle.center, circle.radius, starts[k], step, joints[k],
                     joints[(k + 1) % 4]) for k in range(4))
