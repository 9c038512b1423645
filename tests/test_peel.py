"""Faces no centre sees and no opposite-corner cut splits, cut from corners to sides into
quadrilaterals (layout.peel, through layout.subdivide): held-out 0037's strip under a row
of notches was a free face of unstructured quads at its default size."""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadcnn_wb.core.layout import peel, subdivide
from quadcnn_wb.core.layout.face_geometry import segment_inside
from quadcnn_wb.core.layout.partition_types import Edge
from quadcnn_wb.core.layout.peel import peel_plan
from quadcnn_wb.core.layout.subdivide import split_odd_faces

TOP = [(15.55, -6.3), (11.4, -6.3), (11.4, -7.3), (10.6, -7.3), (10.6, -6.3), (-10.6, -6.3),
       (-10.6, -7.3), (-11.4, -7.3), (-11.4, -6.3), (-15.55, -6.3)]


def _notched_strip():
    """Six corners, counter-clockwise: a strip 3.5 high and 34 long whose top side has two
    notches (as 0037's did), each end a short step up: the diagonals between opposite
    corners cross a notch, and the strip is too long for a centre's spokes."""
    points = [(15.55, -6.3), (-15.55, -6.3), (-16.99, -5.91), (-17.05, -9.8), (17.05, -9.8),
              (16.99, -5.91)]
    corners = [np.array(p, dtype=float) for p in points]
    edges = [Edge(points=np.array(TOP, dtype=float) if a == 0
                  else np.linspace(corners[a], corners[(a + 1) % 6], 9), a=a, b=(a + 1) % 6)
             for a in range(6)]
    return corners, edges, [[(e, True)] for e in range(6)]


def _outline(edges, sides) -> np.ndarray:
    pts = []
    for side in sides:
        for e, forward in side:
            p = edges[e].points if forward else edges[e].points[::-1]
            pts.extend(p[:-1])
    return np.array(pts)


def _area(outline) -> float:
    x, y = outline.T
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


@pytest.mark.parametrize("star", [False, True])
def test_a_notched_strip_becomes_three_blocks_with_cuts_inside_it(star):
    vertices, edges, sides = _notched_strip()
    whole = _outline(edges, sides)
    out, blocks, free = split_odd_faces(vertices, edges, [(list(range(6)), sides, ())], [],
                                        None, star=star)
    assert not free and len(blocks) == 3
    assert all(len(block.corners) == 4 for block in blocks)
    # The blocks tile the face: each a proper counter-clockwise outline, areas adding up.
    areas = [_area(_outline(edges, block.sides)) for block in blocks]
    assert min(areas) > 0.0
    assert sum(areas) == pytest.approx(_area(whole), rel=1e-9)
    cuts = [edge for edge in edges if edge.origin and edge.origin[0] == "split"]
    assert len(cuts) == 2
    for cut in cuts:
        assert segment_inside(whole, cut.points[0], cut.points[0]
                              + (1 - 1e-6) * (cut.points[-1] - cut.points[0]))
        assert abs(cut.points[-1][1] + 9.8) < 1e-9  # the feet on the bottom side


def test_without_the_cuts_the_strip_stays_a_free_face(monkeypatch):
    monkeypatch.setattr(subdivide, "peel_plan", lambda corners, sides: None)
    vertices, edges, sides = _notched_strip()
    _, blocks, free = split_odd_faces(vertices, edges, [(list(range(6)), sides, ())], [], None)
    assert not blocks and len(free) == 1


def test_the_plan_is_the_same_for_a_turned_and_moved_copy():
    vertices, edges, _ = _notched_strip()
    plan = peel_plan(vertices, [edge.points for edge in edges])
    assert plan is not None and len(plan) == 2
    turn = math.radians(37.0)
    rot = np.array([[math.cos(turn), -math.sin(turn)], [math.sin(turn), math.cos(turn)]])
    shift = np.array([1e4, -2e4])
    moved = peel_plan([rot @ v + shift for v in vertices],
                      [edge.points @ rot.T + shift for edge in edges])
    assert [step[:2] for step in moved] == [step[:2] for step in plan]
    assert np.allclose([step[2:] for step in moved], [step[2:] for step in plan], rtol=1e-9,
                       atol=1e-9)


def _ring_half_with_a_bent_end():
    """Five corners, counter-clockwise: a ring's half (radii 10 and 12) whose end at 210°
    bends out to a point between the radii (0043's ring half at its default size): the
    end's two other corners face each other across the strip, so the side point nearest
    either is the other corner."""
    t = np.linspace(math.radians(-30), math.radians(210), 60)
    outer = np.column_stack([12 * np.cos(t), 12 * np.sin(t)])
    inner = np.column_stack([10 * np.cos(t), 10 * np.sin(t)])[::-1]
    bend = 11 * np.array([math.cos(math.radians(214)), math.sin(math.radians(214))])
    corners = [outer[0], outer[-1], bend, inner[0], inner[-1]]
    sides = [outer, np.vstack([outer[-1], bend]), np.vstack([bend, inner[0]]), inner,
             np.vstack([inner[-1], outer[0]])]
    return corners, sides


def test_a_ring_half_with_a_bent_end_is_cut_slanting_across_near_that_end():
    corners, sides = _ring_half_with_a_bent_end()
    assert _area(np.vstack([side[:-1] for side in sides])) > 0.0
    plan = peel_plan(corners, sides)
    assert plan is not None and len(plan) == 1
    c, j, s, _ = plan[0]
    # From an end corner to the other arc, a little along it from the corner facing it
    # (the nearest point, that corner itself, leaves no room for a quad).
    assert (c, j) in ((1, 3), (3, 0))
    cum = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(sides[j], axis=0).T))])
    from_end = s if j == 3 else cum[-1] - s
    assert 0.3 < from_end < 2.0


def test_without_other_feet_the_ring_half_gets_no_plan(monkeypatch):
    monkeypatch.setattr(peel, "FOOT_STEPS", (0,))
    assert peel_plan(*_ring_half_with_a_bent_end()) is None


def _interior_angle(corners, k) -> float:
    a, b, c = (np.asarray(corners[i % len(corners)], dtype=float) for i in (k - 1, k, k + 1))
    u, v = c - b, a - b
    return math.atan2(u[0] * v[1] - u[1] * v[0], float(u @ v)) % (2 * math.pi)


def test_a_cut_from_a_wide_corner_goes_before_a_wider_angle_from_a_narrow_one(monkeypatch):
    # A pentagon (found by search among random ones) whose widest least angle is a cut
    # from a corner under 135°: that corner would get two quads where its angle asks one.
    corners = [np.array(p) for p in ((1.5, 0.4), (1.7, 0.9), (-1.4, 0.5), (-3.4, -0.2),
                                     (-0.7, -1.2))]
    sides = [np.linspace(corners[i], corners[(i + 1) % 5], 5) for i in range(5)]
    (c, _, _, _), = peel_plan(corners, sides)
    assert _interior_angle(corners, c) >= math.radians(135.0)
    monkeypatch.setattr(peel, "WIDE_CORNER", 10.0)
    (other, _, _, _), = peel_plan(corners, sides)
    assert _interior_angle(corners, other) < math.radians(135.0)
