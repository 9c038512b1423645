"""What counts as a corner of a boundary loop, and its angle on the domain's side.

The background mesh makes every corner a node that can start separatrices, the topology
signature counts corners to decide which model fits a domain, and the quality measure
expects round(angle / 90°) quads at a corner node: all three must mean the same joints
and the same angles, so the rule lives here once.
"""

from __future__ import annotations

import math

import numpy as np

from .curves import cross2

CORNER_MIN_TURN = 1e-4  # radians; smaller tangent breaks are smooth joins, not corners


def interior_angle(incoming, outgoing) -> float:
    """Angle on the domain's side (the left) between consecutive curves at their joint."""
    t_in, t_out = incoming.tangent(1.0), outgoing.tangent(0.0)
    turn = math.atan2(cross2(t_in, t_out), float(np.dot(t_in, t_out)))
    return math.pi - turn


def is_corner(angle: float) -> bool:
    """Whether a joint of this interior angle is a corner (not a smooth join)."""
    return abs(angle - math.pi) > CORNER_MIN_TURN
