"""A line that reaches a concave corner hard beside one of its sides (layout.wedges) ends
on the corner's next line, so the faces round the corner keep four corners."""

from __future__ import annotations

import math

import numpy as np
import pytest
from shapes import polygon

from quadcnn_wb.core.field.background import background_mesh
from quadcnn_wb.core.input.domain import domain_from_json
from quadcnn_wb.core.input.pose import diameter
from quadcnn_wb.core.layout.field_rules import corner_endpoint
from quadcnn_wb.core.layout.partition import build_partition
from quadcnn_wb.core.layout.quantize import quantize
from quadcnn_wb.core.layout.streamlines import Endpoint, Streamline
from quadcnn_wb.core.layout.wedges import JUNCTION_REACH, without_corner_wedges
from quadcnn_wb.core.mesh.quadmesh import build_quad_mesh
from quadcnn_wb.core.mesh.quality import scaled_jacobians
from quadcnn_wb.core.pipeline import mesh_domain

L_SHAPE = [[0, 0], [10, 0], [10, 4], [4, 4], [4, 10], [0, 10]]  # 270° corner at (4, 4)


def _l_shape(mirrored: bool):
    points = [[-x, y] for x, y in reversed(L_SHAPE)] if mirrored else L_SHAPE
    return domain_from_json({"loops": [polygon(points)]})


def _on_boundary(domain, p) -> Endpoint:
    """The boundary Endpoint at point p of the outer loop."""
    p = np.asarray(p, dtype=float)
    for segment, curve in enumerate(domain.loops[0]):
        t = curve.project(p)
        if np.allclose(curve.point(t), p):
            return Endpoint("boundary", -1, 0, segment, float(t))
    raise AssertionError(f"{p} is not on the boundary")


def _straight(p0, p1, start, end, n=9):
    return Streamline(np.linspace(np.asarray(p0, float), np.asarray(p1, float), n), start, end)


def _corner_lines(mirrored: bool, arrival_degrees: float):
    """The L-shape's background, and three lines at its 270° corner: the corner's own two
    (to the left side and to the bottom: three right angles) and one arriving from the
    right side or the bottom ``arrival_degrees`` below the corner's side along y = 4."""
    domain = _l_shape(mirrored)
    background = background_mesh(domain, 512)
    sx = -1.0 if mirrored else 1.0
    node = int(np.argmin(np.hypot(*(background.nodes - [4 * sx, 4]).T)))
    assert np.allclose(background.nodes[node], [4 * sx, 4])
    corner = corner_endpoint(background, node)
    here = background.nodes[node]
    left = _straight(here, [0, 4], corner, _on_boundary(domain, [0, 4]))
    down = _straight(here, [4 * sx, 0], corner, _on_boundary(domain, [4 * sx, 0]))
    slope = math.tan(math.radians(arrival_degrees))
    foot = [10 * sx, 4 - 6 * slope] if 6 * slope <= 4 else [(4 + 4 / slope) * sx, 0]
    arriving = _straight(foot, here, _on_boundary(domain, foot), corner)
    return domain, background, [left, down, arriving]


@pytest.mark.parametrize("mirrored", [False, True])
def test_a_line_arriving_beside_a_side_ends_on_the_corners_next_line(mirrored):
    # 20° from the side the line cut the 270° corner into four sectors (90, 90, 70,
    # 20) where the corner asks for three quads; it ends half an element down the
    # corner's own line to the bottom instead: the face beside the side is a strip with
    # four corners, and the face between the two lines one with four too.
    domain, background, lines = _corner_lines(mirrored, 20.0)
    moved = without_corner_wedges(domain, background, lines, 1.0)
    assert moved[:2] == tuple(lines[:2])
    end = moved[2].end
    assert (end.kind, end.index) == ("streamline", 1)
    assert end.param == pytest.approx(JUNCTION_REACH / 4.0)
    sx = -1.0 if mirrored else 1.0
    assert np.allclose(moved[2].points[-1], [4 * sx, 4 - JUNCTION_REACH])
    assert np.allclose(moved[2].points[0], lines[2].points[0])  # its start stays
    partition = build_partition(domain, moved, background.element_size)
    assert not partition.free_faces
    assert len(partition.blocks) == 4
    mesh = build_quad_mesh(domain, partition, quantize(partition, 1.0))
    assert scaled_jacobians(mesh.nodes, mesh.quads).min() > 0.9
    # Ended on the corner, the wedge's face has three corners: split into three blocks
    # round a vertex of its own (two irregular vertices the field does not have).
    before = build_partition(domain, lines, background.element_size)
    assert len(before.blocks) == 6


def test_a_line_arriving_well_inside_the_corner_stays_there():
    # 50° from the side is no wedge: the corner's sectors are what the lines make them.
    domain, background, lines = _corner_lines(False, 50.0)
    assert without_corner_wedges(domain, background, lines, 1.0) == tuple(lines)


def test_no_corner_of_the_crank_web_slots_gets_a_wedge():
    # crankshaft_web_keyway at a hundredth of its diameter: the separatrices from the
    # valence-5 points at the web's root fillets run up the web and into the slots'
    # 300° corners 32° from the side; ended on the corners they left a three-cornered
    # face the length of the web on each side (90 % of the quads in blocks).
    from pathlib import Path

    from quadcnn_wb.core.field.pairs import without_cancelling_pairs
    from quadcnn_wb.core.field.reference import background_and_field
    from quadcnn_wb.core.input.load import load_domain
    from quadcnn_wb.core.input.small_holes import squared_holes
    from quadcnn_wb.core.layout.motorcycle import stop_at_first_hits
    from quadcnn_wb.core.layout.tracing import trace_streamlines

    domain = load_domain(Path(__file__).parent / "corpus" / "crankshaft_web_keyway.brep")
    size = diameter(domain) / 100
    layout = squared_holes(domain, size)
    background, field = background_and_field(layout, 2048, {}, strict=False,
                                             feature_size=size)
    field = without_cancelling_pairs(field, background.element_size)
    lines = stop_at_first_hits(trace_streamlines(layout, background, field),
                               background.element_size, 1e-9 * layout.size)
    moved = without_corner_wedges(layout, background, lines, size)
    changed = [k for k, (a, b) in enumerate(zip(lines, moved)) if a is not b]
    assert len(changed) == 2  # one at each slot's outer corner
    for k in changed:
        assert moved[k].start.kind == "singularity" and moved[k].end.kind == "streamline"
        target = lines[moved[k].end.index]
        assert target.start.kind == "corner"  # the corner's own line
        along = moved[k].end.param * target.length
        assert along == pytest.approx(JUNCTION_REACH * size)
    result = mesh_domain(domain, size=size)
    assert result.structured_share == 1.0, result.problem
