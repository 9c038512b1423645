"""Singular points that cancel (core/field/pairs.py): a valence-3 and a valence-5 point
closer than PAIR element sizes are left out of the layout, closest pairs first."""

from __future__ import annotations

import math

import numpy as np

from quadcnn_wb.core.field.framefield import FrameField, Singularity
from quadcnn_wb.core.field.pairs import PAIR, without_cancelling_pairs


def _field(points):
    sings = tuple(Singularity(xy=np.array(xy, dtype=float), valence=v, triangle=0,
                              directions=np.array([[math.cos(a), math.sin(a)] for a in
                                                   np.arange(v) * 2 * math.pi / v]))
                  for xy, v in points)
    return FrameField(z=np.zeros(1, complex), theta=np.zeros(1), singularities=sings,
                      corner_sources=())


def _kept(field):
    return [(tuple(s.xy.tolist()), s.valence) for s in field.singularities]


def test_a_close_pair_of_opposite_valence_cancels_and_nothing_else_does():
    h = 1.0
    field = _field([((0, 0), 3), ((0.9 * PAIR, 0), 5),  # a pair: gone
                    ((10, 0), 3), ((10, 0.5), 3),  # two of one valence: kept
                    ((20, 0), 5), ((20 + 1.1 * PAIR, 0), 3)])  # too far apart: kept
    assert _kept(without_cancelling_pairs(field, h)) == [
        ((10.0, 0.0), 3), ((10.0, 0.5), 3), ((20.0, 0.0), 5), ((20 + 1.1 * PAIR, 0.0), 3)]


def test_the_closest_partner_is_taken_first():
    # A valence-5 point between two valence-3 points pairs with the nearer one, in any
    # order of the input.
    points = [((0, 0), 3), ((0.5, 0), 5), ((0.8, 0), 3)]
    for order in (points, points[::-1], [points[1], points[2], points[0]]):
        assert _kept(without_cancelling_pairs(_field(order), 1.0)) == [((0.0, 0.0), 3)]


def test_the_sum_of_indices_is_kept():
    rng = np.random.default_rng(7)
    points = [((float(x), float(y)), int(v)) for x, y, v in
              zip(rng.uniform(0, 5, 30), rng.uniform(0, 5, 30), rng.choice([3, 5], 30))]
    before = _field(points)
    after = without_cancelling_pairs(before, 1.0)

    def index(f):
        return sum((4 - s.valence) for s in f.singularities)

    assert len(after.singularities) < len(before.singularities)
    assert index(after) == index(before)


def test_a_part_with_a_cancelling_pair_gets_blocks_without_it():
    # housing_rib's field has a valence-3 and a valence-5 point 1.3 element sizes apart
    # beside its bore; their eight separatrices left a three- and a five-cornered face
    # (93 % of the quads in blocks, 17 irregular vertices).  Without the pair the whole
    # face is blocks and only the singular points that matter are irregular.
    from pathlib import Path

    from quadcnn_wb.core.field.reference import background_and_field
    from quadcnn_wb.core.input.load import load_domain
    from quadcnn_wb.core.pipeline import mesh_domain

    domain = load_domain(Path(__file__).parent / "corpus" / "housing_rib.brep")
    background, field = background_and_field(domain, 2048, {})
    kept = without_cancelling_pairs(field, background.element_size)
    assert len(kept.singularities) == len(field.singularities) - 2
    result = mesh_domain(domain)
    assert result.structured_share == 1.0, result.problem
    assert len(result.reference.field.singularities) == len(kept.singularities)
    assert result.quality["irregular_vertices"] <= len(kept.singularities)
