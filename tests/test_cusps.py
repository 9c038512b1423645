"""Cusps (interior angle below 22.5°: tangent arcs, a crank web's horns): the tip holds
one quad, closed by a kite whose inner corner is a valence-3 vertex (layout.cusps), and
the faces beside it are blocks.  crank_arm_web's cusps, which a singular point's
separatrix runs into, are in test_corpus."""

from __future__ import annotations

import math

import numpy as np
import pytest
from shapes import named_domain, rotation, tip_beside_a_fillet, transform_domain

from quadcnn_wb.core.input.corners import interior_angle
from quadcnn_wb.core.input.domain import domain_from_json
from quadcnn_wb.core.input.pose import diameter
from quadcnn_wb.core.pipeline import mesh_domain


def cusp_tips(domain):
    loop = domain.loops[0]
    return [(loop[k].p1, interior_angle(loop[k], loop[(k + 1) % len(loop)]))
            for k in range(len(loop))
            if interior_angle(loop[k], loop[(k + 1) % len(loop)]) < math.radians(22.5)]


@pytest.mark.parametrize("divisor", [None, 100])
def test_a_crescent_is_two_kites_and_a_ladder(divisor):
    # No singular point: no line runs into either tip, so each gets one traced from it
    # along the field; the one from the first tip meets the second, and both kites cut it.
    domain = named_domain("crescent")
    result = mesh_domain(domain, size=None if divisor is None else diameter(domain) / divisor)
    tips = cusp_tips(domain)
    assert len(tips) == 2 and not result.reference.field.singularities
    assert result.structured_share == 1.0, result.problem
    mesh = result.mesh
    for tip, _ in tips:
        node = np.nonzero(np.hypot(*(mesh.nodes - tip).T) < 1e-9)[0]
        assert len(node) == 1 and np.sum(mesh.quads == node[0]) == 1
        (quad,) = np.nonzero((mesh.quads == node[0]).any(axis=1))[0]
        opposite = mesh.quads[quad][(list(mesh.quads[quad]).index(node[0]) + 2) % 4]
        assert np.sum(mesh.quads == opposite) == 3
    # Irregular: the kites' inner corners only; the worst quad is a tip's, about as good
    # as its angle allows (the tip quad's sides are chords of the arcs).
    assert result.quality["irregular_vertices"] == 2
    worst_tip = min(math.sin(angle) for _, angle in tips)
    assert 0.95 * worst_tip <= result.quality["min_scaled_jacobian"] <= worst_tip


def test_a_crescent_gets_the_same_mesh_in_every_pose():
    loops = {"loops": named_domain("crescent").to_json()["loops"]}
    seen = set()
    for matrix, shift in [(rotation(0), (0, 0)), (rotation(37), (0, 0)),
                          (rotation(211, mirror=True), (1e4, -1e4)),
                          (rotation(123, scale=1e-3), (0, 0))]:
        result = mesh_domain(domain_from_json(transform_domain(loops, matrix, shift)))
        q = result.quality
        seen.add((q["blocks"], q["quads"], q["irregular_vertices"], result.structured_share))
    assert len(seen) == 1


@pytest.mark.parametrize("nudge", [-1e-12, 0.0, 1e-12])
def test_a_tip_between_tangent_curves_is_read_by_the_curves_not_by_round_off(nudge):
    # An arc arriving at the tip heading up, and a line leaving it straight down: the
    # tangent turns back, and the sign of that half turn was round-off (a JSON round
    # trip of a blend plate read its horn as 360° instead of 0°, and the face fell
    # back).  Where the line lies on the domain's side of the arc, the tip is a cusp
    # (0°); the same curves the other way round make a 360° notch.
    from quadcnn_wb.core.input.curves import Arc, Line

    r = 5.0
    a = np.radians([60.0, 30.0, 0.0])
    points = np.column_stack([r - r * np.cos(a), -r * np.sin(a)])
    arc = Arc.through(*points)  # arrives at the origin heading up
    line = Line(np.zeros(2), np.array([nudge, -5.0]))
    assert interior_angle(arc, line) == pytest.approx(0.0, abs=1e-5)
    back_line = Line(np.array([nudge, -5.0]), np.zeros(2))
    back_arc = Arc.through(*points[::-1])
    assert interior_angle(back_line, back_arc) == pytest.approx(2 * math.pi, abs=1e-5)


@pytest.mark.parametrize("divisor", [None, 100])
def test_a_tangent_horns_kite_sits_where_the_horn_is_half_an_element_wide(divisor):
    # blend_horn_square's horn: a quarter arc tangent to a straight side.  One element
    # from the tip its sides are a fiftieth of an element apart at diameter/100, and the
    # kite there was a sliver (worst scaled Jacobian 0.022; 0.077 at the default size);
    # a horn elsewhere folded its kite and left the whole face unstructured.
    from pathlib import Path

    from quadcnn_wb.core.input.load import load_domain

    domain = load_domain(Path(__file__).parent / "corpus" / "blend_horn_square.brep")
    result = mesh_domain(domain, size=None if divisor is None else diameter(domain) / divisor)
    assert result.structured_share == 1.0, result.problem
    assert result.quality["min_scaled_jacobian"] > 0.1


def test_the_line_from_a_tangent_horns_tip_keeps_to_its_middle():
    # blend_horn_plate's horns: a line x = 10 and a circle of radius 6 about (16, 150)
    # (and about (16, 0)), tangent at the tips.  Traced along the field from the tip,
    # the line drifted onto the straight side and ran along it to a corner, leaving a
    # two-cornered sliver beside it (98 % of the part in blocks); it now follows the
    # horn's middle while the horn is narrower than 1.5 elements, and every face is a block.
    from pathlib import Path

    from quadcnn_wb.core.input.load import load_domain

    domain = load_domain(Path(__file__).parent / "corpus" / "blend_horn_plate.brep")
    result = mesh_domain(domain)
    assert result.structured_share == 1.0, result.problem
    seen = 0
    for line in result.reference.streamlines:
        if line.start.kind == line.end.kind == "boundary":
            continue  # a kite's arms, which cross the horn from side to side
        for tip_y in (150.0, 0.0):
            points = np.asarray(line.points)
            near = points[(np.abs(points[:, 1] - tip_y) < 3.8) & (points[:, 0] < 13.0)]
            to_line = near[:, 0] - 10.0
            to_arc = np.hypot(near[:, 0] - 16.0, near[:, 1] - tip_y) - 6.0
            assert np.all(np.minimum(to_line, to_arc) > 0.4 * (to_line + to_arc))
            seen += len(near)
    assert seen >= 8


@pytest.mark.parametrize("size", [0.6, 1.0])
def test_only_the_tips_own_corner_of_a_tip_quad_is_excused(size):
    # The three blocks round a 20-degree tip's singular point, half an element across,
    # collapsed onto the tip's side: the tip's quad had its 4th corner on that side, flat
    # (0.006), and went out as the worst element because the whole quad was excused.
    # Only the tip's own corner is: the quad is a degenerate element, its blocks are
    # given up and the tip is meshed without the structure it cannot hold.
    domain = domain_from_json({"loops": [tip_beside_a_fillet()]})
    result = mesh_domain(domain, size=size)
    assert result.structured_share == 1.0, result.problem
    assert result.quality["min_scaled_jacobian"] > 0.5
    assert result.quality["irregular_vertices"] == 0


def test_a_mesh_whose_only_poor_quads_sit_at_tips_is_fair_but_at_tips():
    """What lets the pipeline take a finer layout all in blocks without finishing the
    first one (pipeline._best_layout): the corpus's plate with two tangent horns at
    diameter/100 spent 11 s finishing a first layout that lost.  Its mesh is unfair by
    the tips alone; a mesh with no tip is never excused."""
    from conftest import REPO

    from quadcnn_wb.core.input.load import load_domain
    from quadcnn_wb.core.rounds import fair_but_at_tips, mesh_key

    horns = load_domain(REPO / "tests" / "corpus" / "blend_horn_plate.brep")
    size = diameter(horns) / 100
    result = mesh_domain(horns, size)
    assert result.structured_share == 1.0
    assert not mesh_key(result.mesh)[0]  # a tip quad below FAIR_JACOBIAN
    assert fair_but_at_tips(result.mesh, result.reference.mesh, size)

    # No tip: nothing to excuse, whatever the worst element (the rule is for tips only).
    square = domain_from_json({"loops": [[{"line": [[0, 0], [1, 0]]}, {"line": [[1, 0], [1, 1]]},
                                          {"line": [[1, 1], [0, 1]]}, {"line": [[0, 1], [0, 0]]}]]})
    result = mesh_domain(square)
    assert not fair_but_at_tips(result.mesh, result.reference.mesh, result.size)
