"""Domain JSON v1 input: the shared examples load, and loops come out oriented and exact."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import circle, rect

from quadcnn_wb.core.input.curves import Arc, loop_signed_area
from quadcnn_wb.core.input.domain import domain_from_json
from quadcnn_wb.core.input.load import load_domain

EXPECTED_AREA = {
    "concave": 2.0 - 0.6 * 0.5,
    "four_hole": 4.0 - 4 * math.pi * 0.22**2,
    "l_shape": 3.0,
    "plate_hole": 2.0 - math.pi * 0.25**2,
    "semicircle": math.pi / 2,
}


def test_shared_examples_load_with_exact_area(example_path):
    domain = load_domain(example_path)
    assert domain.area == pytest.approx(EXPECTED_AREA[example_path.stem], rel=1e-12)
    assert loop_signed_area(domain.loops[0]) > 0
    assert all(loop_signed_area(loop) < 0 for loop in domain.loops[1:])


def test_loops_given_clockwise_are_reoriented_and_hole_direction_flipped():
    outer = rect(2, 1)[::-1]
    outer = [{"line": seg["line"][::-1]} for seg in outer]  # clockwise
    domain = domain_from_json({"loops": [outer, circle(1, 0.5, 0.2)]})
    assert loop_signed_area(domain.loops[0]) == pytest.approx(2.0)
    assert loop_signed_area(domain.loops[1]) == pytest.approx(-math.pi * 0.04)


def test_consecutive_curves_meet_exactly():
    wobble = 1e-11
    loop = [{"line": [[0, 0], [1, 0]]}, {"line": [[1, wobble], [1, 1]]},
            {"arc": [[1, 1], [0.5, 1.5], [0, 1]]}, {"line": [[0, 1], [0, 0]]}]
    domain = domain_from_json({"loops": [loop]})
    curves = domain.loops[0]
    for a, b in zip(curves, curves[1:] + curves[:1]):
        assert np.array_equal(a.p1, b.p0)


def test_arc_through_three_points_is_the_true_circle():
    domain = domain_from_json({"loops": [[{"line": [[-1, 0], [1, 0]]},
                                          {"arc": [[1, 0], [0, 1], [-1, 0]]}]]})
    arc = domain.loops[0][1]
    assert isinstance(arc, Arc)
    assert np.allclose(arc.center, [0, 0], atol=1e-15)
    t = np.linspace(0, 1, 101)
    assert np.allclose(np.hypot(*arc.point(t).T), 1.0, atol=1e-15)
    assert arc.project(arc.point(0.37)) == pytest.approx(0.37, abs=1e-14)


def test_arc_larger_than_half_circle_keeps_its_side():
    # Notch: an arc bulging into the rectangle through (1, 0.9) must be the major-arc side.
    loop = [{"line": [[0, 0], [2, 0]]}, {"line": [[2, 0], [2, 2]]},
            {"line": [[2, 2], [1.2, 2]]}, {"arc": [[1.2, 2], [1, 1.5], [0.8, 2]]},
            {"line": [[0.8, 2], [0, 2]]}, {"line": [[0, 2], [0, 0]]}]
    domain = domain_from_json({"loops": [loop]})
    arc = domain.loops[0][3]
    assert arc.midpoint() == pytest.approx(np.array([1.0, 1.5]), abs=1e-12)
    assert domain.area < 4.0


def test_units_kept_and_round_trip_through_json():
    domain = domain_from_json({"units": "m", "loops": [rect(3, 2), circle(1, 1, 0.5)]})
    again = domain_from_json(domain.to_json())
    assert again.units == "m"
    assert again.area == pytest.approx(domain.area, rel=1e-14)


def test_nearly_touching_loops_are_valid():
    gap = 1e-6
    domain = domain_from_json({"loops": [rect(2, 1), circle(1, 0.5, 0.5 - gap)]})
    assert domain.holes == 1
