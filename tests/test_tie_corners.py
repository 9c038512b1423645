"""Corners at odd multiples of 45° (input.corners.odd_ties): a loop whose corners,
rounded the even way, fall short of its whole turn by as many quarter turns as it has
ties that can make it up takes the odd count there, so the field needs no singular point
for it; where more ties could make it up than needed, none does."""

from __future__ import annotations

import math

import pytest
from shapes import polygon, rotation, transform_domain

from quadcnn_wb.core.field import background
from quadcnn_wb.core.input.corners import interior_angle, odd_ties
from quadcnn_wb.core.input.domain import domain_from_json
from quadcnn_wb.core.pipeline import mesh_domain

# A pocket whose fourth corner is a 45° arc ending on the pocket's floor at 225° (as in
# AnalysisSitus' blends/0016: four arcs of 45° in all, then a 45° kink): the arc leaves
# the floor at an angle no quarter-turn count fits, and rounded the even way the hole's
# corners make three quarter turns where its turn is four.
_S = math.sqrt(0.5)
_KINK = [25.0 + 5.0 * _S, 8.0 - 5.0 * _S]
POCKET_WITH_A_KINK = [
    [{"line": [[0, 0], [40, 0]]}, {"line": [[40, 0], [40, 20]]},
     {"line": [[40, 20], [0, 20]]}, {"line": [[0, 20], [0, 0]]}],
    [{"line": [[10, _KINK[1]], [10, 15]]}, {"line": [[10, 15], [30, 15]]},
     {"line": [[30, 15], [30, 8]]},
     {"arc": [[30, 8], [25.0 + 5.0 * math.cos(math.radians(22.5)),
                        8.0 - 5.0 * math.sin(math.radians(22.5))], _KINK]},
     {"line": [_KINK, [10, _KINK[1]]]}],
]


def test_the_kink_is_a_tie_that_takes_the_odd_count():
    domain = domain_from_json({"loops": POCKET_WITH_A_KINK})
    hole = domain.loops[1]
    assert math.degrees(interior_angle(hole[3], hole[4])) == pytest.approx(225.0)
    assert odd_ties(domain) == {(1, 4)}


@pytest.mark.parametrize("matrix", [None, rotation(37), rotation(211, 1e3, mirror=True)],
                         ids=["as drawn", "turned", "turned+scaled+mirrored"])
def test_the_pocket_needs_no_singular_point_and_is_all_blocks(matrix):
    data = {"loops": POCKET_WITH_A_KINK}
    domain = domain_from_json(data if matrix is None else
                              transform_domain(data, matrix, shift=(1e4, -7.0)))
    result = mesh_domain(domain)
    assert result.reference.field.singularities == ()
    assert result.structured_share == 1.0, result.problem
    assert result.quality["min_scaled_jacobian"] > 0.5


def test_rounded_the_even_way_the_kink_seeds_a_singular_point(monkeypatch):
    # What the rule saves: with the tie rounded to 2 quads, the hole's corners turn by
    # three quarters, and the field makes up the fourth with a valence-5 point.
    monkeypatch.setattr(background, "odd_ties", lambda domain: frozenset())
    result = mesh_domain(domain_from_json({"loops": POCKET_WITH_A_KINK}))
    assert [s.valence for s in result.reference.field.singularities] == [5]


@pytest.mark.parametrize("corners", [
    [[0, 0], [4, 0], [4, 2.5], [3.5, 3], [0, 3]],  # two 135° ties, one quarter short
    [[0.5, 0], [3.5, 0], [4, 0.5], [4, 2.5], [3.5, 3], [0.5, 3], [0, 2.5], [0, 0.5]],
], ids=["one corner chamfered", "every corner chamfered"])
def test_where_more_ties_could_make_it_up_than_needed_none_does(corners):
    assert odd_ties(domain_from_json({"loops": [polygon(corners)]})) == frozenset()
