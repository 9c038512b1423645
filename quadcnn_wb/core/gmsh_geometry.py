"""A domain as gmsh geometry: OCC curves in the pose's unit coordinates.

The background triangle mesh (field/background.py) and gmsh's own quad meshes
(mesh/gmsh_quads.py) hand gmsh the same geometry, built the same way, so that a moved,
turned or rescaled copy of a part gives gmsh the very same numbers and so the same mesh.
"""

from __future__ import annotations

import gmsh
import numpy as np

from .input.curves import Arc
from .input.domain import Domain
from .input.pose import Pose

UNIT_DIGITS = 9  # unit coordinates are rounded to this many decimals before gmsh: far
#                 above the round-off of a part moved by 1e4 of its size (~1e-12)


def unit(value):
    """Round unit-scaled values so that a moved or rescaled copy of a part gives gmsh the
    very same numbers (not numbers a rounding error apart, which can flip a Delaunay
    decision and change the whole mesh)."""
    return np.round(value, UNIT_DIGITS) + 0.0  # + 0.0: no negative zeros either


def _unit_loops(domain: Domain, pose: Pose, splits=None):
    """The loops in unit coordinates, in an order that depends on the shape alone.

    Each loop is a list of (loop index, segment index, start, middle or None, end) with the
    domain on the left in the pose (a mirrored pose reverses the loops), starting at its
    lowest-then-leftmost vertex; holes sorted by that vertex.  Full circles are
    (loop index, centre, radius).  ``splits``: {(loop, segment): parameters, ascending}
    of curves cut there (each piece is one entry, with the same indices).
    """
    splits = splits or {}
    loops = []
    for li, loop in enumerate(domain.loops):
        if len(loop) == 1 and isinstance(loop[0], Arc) and loop[0].is_full:
            c = loop[0]
            loops.append((li, unit(pose.to_unit(c.center)), unit(c.radius / pose.scale)))
            continue
        pieces = []
        for si, c in enumerate(loop):
            ends = (0.0, *splits.get((li, si), ()), 1.0)
            for t0, t1 in zip(ends[:-1], ends[1:]):
                mid = unit(pose.to_unit(c.point(0.5 * (t0 + t1)))) if isinstance(c, Arc) \
                    else None
                pieces.append((li, si, unit(pose.to_unit(c.point(t0))), mid,
                               unit(pose.to_unit(c.point(t1)))))
        if pose.mirrored:
            pieces = [(li, si, end, mid, start) for li, si, start, mid, end in pieces[::-1]]
        first = min(range(len(pieces)), key=lambda k: (pieces[k][2][1], pieces[k][2][0]))
        loops.append(pieces[first:] + pieces[:first])

    def start_key(loop):
        point = loop[1] if isinstance(loop, tuple) else loop[0][2]
        return (point[1], point[0])

    return [loops[0]] + sorted(loops[1:], key=start_key)


def build_geometry(domain: Domain, pose: Pose, splits=None) -> dict:
    """OCC curves for every domain curve, in unit coordinates; returns tag -> (loop, seg).

    Into the current gmsh model (inside a gmsh_session); the caller meshes it.
    ``splits``: {(loop, segment): parameters, ascending} where a curve gets vertices (and
    so mesh nodes) of its own; every piece maps to the curve's (loop, seg)."""
    occ = gmsh.model.occ
    curve_tags = {}
    loop_tags = []
    helpers = []
    for loop in _unit_loops(domain, pose, splits):
        if isinstance(loop, tuple):
            li, q, radius = loop
            tag = occ.addCircle(q[0], q[1], 0.0, radius)
            curve_tags[tag] = (li, 0)
            loop_tags.append(occ.addCurveLoop([tag]))
            continue
        vertices = [occ.addPoint(start[0], start[1], 0.0) for _, _, start, _, _ in loop]
        tags = []
        for k, (li, si, _, mid, _) in enumerate(loop):
            start, end = vertices[k], vertices[(k + 1) % len(loop)]
            if mid is not None:
                helper = occ.addPoint(mid[0], mid[1], 0.0)
                helpers.append(helper)
                tag = occ.addCircleArc(start, helper, end, center=False)
            else:
                tag = occ.addLine(start, end)
            curve_tags[tag] = (li, si)
            tags.append(tag)
        loop_tags.append(occ.addCurveLoop(tags))
    occ.addPlaneSurface(loop_tags)
    if helpers:
        occ.remove([(0, t) for t in helpers])
    occ.synchronize()
    return curve_tags
