"""Round holes below the element size read as squares (core/input/small_holes.py): no
singular points round them, their four corners turned to the surrounding boundary, alike
in every pose."""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadcnn_wb.core.input.domain import domain_from_json
from quadcnn_wb.core.input.small_holes import SMALL_HOLE, is_quartered, squared_holes
from quadcnn_wb.core.input.transform import similarity, transform_domain_json
from quadcnn_wb.core.pipeline import mesh_domain

SIZE = 4.0


def plate_json(diameter, centres):
    pts = [[0, 0], [100, 0], [100, 50], [0, 50]]
    outer = [{"line": [pts[i], pts[(i + 1) % 4]]} for i in range(4)]
    holes = [[{"circle": {"center": c, "radius": diameter / 2}}] for c in centres]
    return {"loops": [outer] + holes}


def corners(domain, loop):
    """The square's corners: the middles of the hole's quarter arcs."""
    return np.array([arc.point(0.5) for arc in domain.loops[loop]])


def test_a_small_hole_is_four_quarter_arcs_square_to_the_plate():
    domain = squared_holes(domain_from_json(plate_json(4.0, [[50, 25]])), SIZE)
    assert is_quartered(domain.loops[1])
    directions = np.degrees(np.arctan2(*(corners(domain, 1) - [50, 25]).T[::-1])) % 90
    assert directions == pytest.approx([45.0] * 4)


def test_a_hole_of_two_sizes_or_more_stays_a_circle():
    data = plate_json(SMALL_HOLE * SIZE, [[50, 25]])
    domain = squared_holes(domain_from_json(data), SIZE)
    assert len(domain.loops[1]) == 1 and domain.loops[1][0].is_full


@pytest.mark.parametrize("diameter, centres", [(4.0, [[50, 25]]),
                                               (6.0, [[30, 20], [70, 30]])])
def test_a_plate_with_small_holes_needs_no_singular_point(diameter, centres):
    result = mesh_domain(domain_from_json(plate_json(diameter, centres)), size=SIZE)
    assert result.structured_share == 1.0, result.problem
    assert len(result.reference.field.singularities) == 0
    # Irregular: the squares' corners only (three quads where the rim is smooth).
    assert result.quality["irregular_vertices"] == 4 * len(centres)
    assert result.quality["min_scaled_jacobian"] > 0.9
    # The result holds the part as given (the exports name its curves): round holes.
    assert all(len(loop) == 1 and loop[0].is_full for loop in result.domain.loops[1:])


@pytest.mark.parametrize("degrees, mirror, scale", [(37.0, False, 1.0), (211.0, True, 1e-3),
                                                    (90.0, False, 1e3)])
def test_a_turned_copy_turns_its_squares_alike(degrees, mirror, scale):
    data = plate_json(4.0, [[50, 25], [20, 10]])
    matrix = similarity(degrees, scale, mirror)
    shift = np.array([1e4, -3e3]) * scale
    base = squared_holes(domain_from_json(data), SIZE)
    moved = squared_holes(domain_from_json(transform_domain_json(data, matrix, shift)),
                          SIZE * scale)
    for loop in range(1, len(base.loops)):
        expected = corners(base, loop) @ matrix.T + shift
        got = corners(moved, loop)
        # The same four corners, in whichever order the copy's loop runs.
        distance = np.hypot(*(got[:, None, :] - expected[None, :, :]).transpose(2, 0, 1))
        assert distance.min(axis=1).max() < 1e-9 * 100 * scale
        assert math.isclose(moved.loops[loop][0].radius, base.loops[loop][0].radius * scale)


@pytest.mark.parametrize("outer_radius, squared", [(3.0, False), (4.0, True)])
def test_a_hole_in_a_boss_thinner_than_an_element_stays_round(outer_radius, squared):
    # A 4 mm hole at 1.5 mm elements is small; in a boss whose wall is 1 mm its ring of
    # quads follows the boss (engine_top's bosses), in a 2 mm wall it is a square.
    data = {"loops": [[{"circle": {"center": [0, 0], "radius": outer_radius}}],
                      [{"circle": {"center": [0, 0], "radius": 2.0}}]]}
    domain = squared_holes(domain_from_json(data), 1.5)
    assert is_quartered(domain.loops[1]) is squared
