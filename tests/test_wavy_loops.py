"""A loop that is one chain of turns below the element size all round (a knurled ring,
a serrated hole) is read at the element's scale: smooth, every joint flat, the field
following its mean tangent (input.features._wavy_loop).  A loop with corners at the
element's scale is read as it is."""

from __future__ import annotations

import math

import numpy as np
import pytest

from quadcnn_wb.core.input.domain import domain_from_json
from quadcnn_wb.core.input.features import boundary_features, mean_tangents
from quadcnn_wb.core.input.transform import similarity, transform_domain_json
from quadcnn_wb.core.pipeline import mesh_domain


def knurled_ring(teeth=200, outer=50.0, depth=0.6, inner=40.0):
    """A ring whose outer rim is ``teeth`` trapezoidal teeth of straight lines."""
    points = []
    for k in range(teeth):
        a0, w = 2 * math.pi * k / teeth, 2 * math.pi / teeth
        for frac, r in ((0.0, outer - depth), (0.2, outer), (0.5, outer), (0.7, outer - depth)):
            points.append([r * math.cos(a0 + frac * w), r * math.sin(a0 + frac * w)])
    rim = [{"line": [points[i], points[(i + 1) % len(points)]]} for i in range(len(points))]
    return {"loops": [rim, [{"circle": {"center": [0.0, 0.0], "radius": inner}}]]}


def test_a_knurled_rim_is_one_flat_feature_at_the_default_size():
    domain = domain_from_json(knurled_ring())
    wavy = [f for f in boundary_features(domain, domain.size / 40) if f.window]
    assert len(wavy) == 1 and len(wavy[0].joints) == len(domain.loops[0])
    # At a size that resolves the teeth the rim is read as it is.
    assert not any(f.window for f in boundary_features(domain, 0.2))


def test_the_mean_tangent_of_a_knurled_rim_is_the_circles():
    domain = domain_from_json(knurled_ring())
    loop = domain.loops[0]
    total = sum(c.length for c in loop)
    s = np.linspace(0.0, total, 50, endpoint=False)
    tangents = mean_tangents(loop, s, 2.5)
    # Points along the rim: its tangent there is square to the radius, within a few degrees.
    t = np.linspace(0.0, 1.0, 9)[:-1]
    poly = np.concatenate([c.point(t) for c in loop])
    along = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(poly, axis=0).T))])
    where = np.column_stack([np.interp(s * along[-1] / total, along, poly[:, k]) for k in (0, 1)])
    radial = where / np.hypot(*where.T)[:, None]
    assert np.degrees(np.abs(np.arcsin(np.abs((tangents * radial).sum(axis=1))))).max() < 6.0


def test_a_knurled_ring_is_one_block_with_no_irregular_vertex():
    result = mesh_domain(domain_from_json(knurled_ring()))
    assert result.structured_share == 1.0, result.problem
    assert len(result.reference.field.singularities) == 0
    assert result.quality["irregular_vertices"] == 0
    assert result.quality["min_scaled_jacobian"] > 0.9


@pytest.mark.parametrize("degrees, mirror, scale", [(37.0, False, 1.0), (211.0, True, 1e-3)])
def test_a_turned_knurled_ring_gets_the_same_mesh(degrees, mirror, scale):
    data = knurled_ring()
    base = mesh_domain(domain_from_json(data)).quality
    moved = mesh_domain(domain_from_json(transform_domain_json(
        data, similarity(degrees, scale, mirror), np.zeros(2)))).quality
    assert [moved[k] for k in ("blocks", "quads", "irregular_vertices")] == \
        [base[k] for k in ("blocks", "quads", "irregular_vertices")]


def test_a_serrated_rectangle_keeps_its_corners():
    """Teeth all round a 40 x 20 plate chain into one loop, but its mean tangent turns
    by a quarter at each corner: read as it is (its corners stay corners)."""
    points = []
    for (x0, y0), (x1, y1) in (((0, 0), (40, 0)), ((40, 0), (40, 20)), ((40, 20), (0, 20)),
                               ((0, 20), (0, 0))):
        n = int(round(math.hypot(x1 - x0, y1 - y0) / 0.5))
        dx, dy = (x1 - x0) / n, (y1 - y0) / n
        nx, ny = dy / math.hypot(dx, dy) * 0.1, -dx / math.hypot(dx, dy) * 0.1
        for k in range(n):
            points.append([x0 + k * dx, y0 + k * dy])
            points.append([x0 + (k + 0.5) * dx + nx, y0 + (k + 0.5) * dy + ny])
    rim = [{"line": [points[i], points[(i + 1) % len(points)]]} for i in range(len(points))]
    domain = domain_from_json({"loops": [rim]})
    assert not any(f.window for f in boundary_features(domain, domain.size / 40))
