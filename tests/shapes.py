"""Domain JSON builders for the tests' own shapes (beyond ../shared/examples)."""

from __future__ import annotations

import math

import numpy as np


def rect(w, h, x0=0.0, y0=0.0):
    p = [[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0 + h]]
    return [{"line": [p[i], p[(i + 1) % 4]]} for i in range(4)]


def circle(cx, cy, r):
    return [{"circle": {"center": [cx, cy], "radius": r}}]


def polygon(points):
    return [{"line": [list(points[i]), list(points[(i + 1) % len(points)])]}
            for i in range(len(points))]


def regular_polygon(n, r=1.0):
    return polygon([[r * math.cos(a), r * math.sin(a)]
                    for a in np.linspace(0, 2 * math.pi, n + 1)[:-1]])


def thin_wall():
    """An L-shaped wall 1 thick with a 0.08 step up and down along its inner edge and a
    fillet of radius 0.08 in its concave corner: features of a quarter of the default
    element size (0.32), like motor_c_plate's 0.6 mm steps and 1 mm fillets."""
    r = 0.08
    mid = [9 - r + r * math.cos(math.radians(45)), 7 - r + r * math.sin(math.radians(45))]
    return polygon([[0, 8], [0, 7], [1, 7], [1, 7.08], [5, 7.08], [5, 7], [9 - r, 7]])[:-1] + [
        {"arc": [[9 - r, 7], mid, [9, 7 - r]]}] + polygon([[9, 7 - r], [9, 0], [10, 0],
                                                          [10, 8], [0, 8]])[:-1]


def tip_beside_a_fillet(radius=45.0):
    """A 20-degree tip where a fillet of radius 1 runs into a gently curved side (radius
    ``radius``), with no tangent: held-out 0043's corner (grabcad 204211), in its own
    units.  The tip's region is about half an element at sizes 0.6 to 1.2."""
    tip = np.array([-0.95, -math.sqrt(1 - 0.95 ** 2)])
    centre = tip + radius * np.array([math.cos(math.radians(3.58)),
                                      math.sin(math.radians(3.58))])
    foot = np.array([centre[0] - math.sqrt(radius ** 2 - (-6 - centre[1]) ** 2), -6.0])
    a0, a1 = (math.atan2(p[1] - centre[1], p[0] - centre[0]) for p in (tip, foot))
    side_mid = centre + radius * np.array([math.cos(0.5 * (a0 + a1)), math.sin(0.5 * (a0 + a1))])
    fillet_mid = [math.cos(math.radians(-125)), math.sin(math.radians(-125))]
    return [{"arc": [tip.tolist(), side_mid.tolist(), foot.tolist()]},
            {"line": [foot.tolist(), [8, -6]]}, {"line": [[8, -6], [8, -1]]},
            {"line": [[8, -1], [0, -1]]}, {"arc": [[0, -1], fillet_mid, tip.tolist()]}]


def stadium():
    return [{"line": [[0, 0], [2, 0]]}, {"arc": [[2, 0], [3, 1], [2, 2]]},
            {"line": [[2, 2], [0, 2]]}, {"arc": [[0, 2], [-1, 1], [0, 0]]}]


def crescent():
    return [{"arc": [[0, 0], [5, 4], [10, 0]]}, {"arc": [[10, 0], [5, 3], [0, 0]]}]


from quadcnn_wb.core.input.transform import similarity as rotation  # noqa: E402,F401
from quadcnn_wb.core.input.transform import transform_domain_json as transform_domain  # noqa: E402,F401

# name -> (loops, expected valence-3 count, expected valence-5 count)
OWN_SHAPES = {
    "disk": ([circle(0, 0, 1)], 4, 0),
    "annulus": ([circle(0, 0, 1), circle(0.1, 0, 0.4)], 0, 0),
    "triangle": ([polygon([[0, 0], [1, 0], [0.5, 0.9]])], 1, 0),
    "plate, 1 hole": ([rect(3, 2), circle(1.5, 1, 0.4)], 0, 4),
    "plate, 2 holes": ([rect(3, 2), circle(0.8, 1, 0.3), circle(2.2, 1, 0.3)], 0, 8),
    "plate, 3 holes": ([rect(4, 2), circle(0.8, 1, 0.3), circle(2, 1, 0.3),
                        circle(3.2, 1.1, 0.3)], 0, 12),
    "stadium": ([stadium()], 4, 0),
    "pentagon": ([regular_polygon(5)], 0, 1),
    "hexagon": ([regular_polygon(6)], 0, 2),
    "square with square hole": ([rect(3, 3), rect(1, 1, 1, 1)], 0, 0),
    # 135° chamfers and a 225°/135° step lie exactly between two quad counts per corner:
    # the field winds as corner_quads says (before, round-off seeded 83-105 spurious
    # valence-5 points at them in the input's own pose)
    "chamfered plate": ([polygon([[0.5, 0], [3.5, 0], [4, 0.5], [4, 2.5], [3.5, 3], [0.5, 3],
                                  [0, 2.5], [0, 0.5]])], 4, 0),
    "plate with a 45° step": ([polygon([[0, 0], [3, 0], [3, 1], [2, 1], [1, 2], [0, 2]])], 0, 0),
    # Steps and a concave fillet far below the element size are part of the side they sit
    # on, and the fillet one concave corner: no singular point, no streamline beside them.
    "thin wall": ([thin_wall()], 0, 0),
    "T shape": ([polygon([[0, 0], [1, 0], [1, 2], [2, 2], [2, 3], [-1, 3], [-1, 2],
                          [0, 2]])], 0, 0),
    # Two arcs through the same ends, 15.4° apart there: two cusps, which make up the
    # disk's count (the field carries on through them), so no singular point.
    "crescent": ([crescent()], 0, 0),
}


def named_domain(name):
    """A shared example (by file stem) or one of OWN_SHAPES, as a Domain."""
    from conftest import EXAMPLE_NAMES, SHARED_EXAMPLES

    from quadcnn_wb.core.input.domain import domain_from_json
    from quadcnn_wb.core.input.load import load_domain

    if name in EXAMPLE_NAMES:
        return load_domain(SHARED_EXAMPLES / f"{name}.json")
    return domain_from_json({"loops": OWN_SHAPES[name][0]})
