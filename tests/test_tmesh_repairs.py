"""What the T-mesh does with faces and arcs that are too small or too many-cornered for a
block: a short boundary arc beside a trace's end takes no segment, so the strip it
bounds collapses; a six-cornered face is cut in two between opposite corners; as the last
resort, faces of more corners or with reflex ones are split round a centre; a lens takes
its two sharpest bends as corners, and of bends tied for that, the pair that balances its
sides."""

from __future__ import annotations

import numpy as np
import pytest
from shapes import polygon

from quadcnn_wb.core.input.domain import domain_from_json
from quadcnn_wb.core.layout.partition import build_partition
from quadcnn_wb.core.layout.partition_types import block_area_share, free_blocks
from quadcnn_wb.core.layout.quantize import quantize
from quadcnn_wb.core.layout.streamlines import Endpoint, Streamline
from quadcnn_wb.core.mesh.quadmesh import build_quad_mesh
from quadcnn_wb.core.mesh.quality import scaled_jacobians


def _rectangle():
    return domain_from_json({"loops": [polygon([[0, 0], [10, 0], [10, 4], [0, 4]])]})


def _vertical(x, upwards, top_segment=2, top_from=10.0):
    """A field line across the 10 x 4 rectangle at x, ending on its bottom and on its
    top (curve ``top_segment``, running from x = top_from to 0)."""
    bottom = Endpoint("boundary", -1, 0, 0, x / 10)
    top = Endpoint("boundary", -1, 0, top_segment, (top_from - x) / top_from)
    ys = np.linspace(0, 4, 9) if upwards else np.linspace(4, 0, 9)
    points = np.column_stack([np.full(9, float(x)), ys])
    return Streamline(points, bottom, top) if upwards else Streamline(points, top, bottom)


def test_a_strip_between_lines_a_fifth_of_an_element_apart_collapses_to_one_line():
    # Two traces that reach the rim 0.2 sizes apart (a separatrix and a corner's line
    # that ended just beside it): the rim between them may take no segment, so the
    # strip they bound has no width and the two lines are one mesh line half-way
    # between them.  Held to a segment, the strip was a column of slivers (or, beside
    # a corner, left no counts at all).
    domain = _rectangle()
    lines = [_vertical(5.0, True), _vertical(5.2, False)]
    partition = build_partition(domain, lines, 1.0)
    assert len(partition.blocks) == 3
    counts = quantize(partition, 1.0)
    short = [e for e, edge in enumerate(partition.edges)
             if edge.is_boundary and edge.length < 0.5]
    assert len(short) == 2 and all(counts[e] == 0 for e in short)
    mesh = build_quad_mesh(domain, partition, counts)
    assert len(mesh.quads) == 40  # 10 columns of 4, no column for the strip
    assert scaled_jacobians(mesh.nodes, mesh.quads).min() > 0.9
    on_rim = mesh.nodes[np.isclose(mesh.nodes[:, 1], 0.0)]
    assert np.any(np.isclose(on_rim[:, 0], 5.1))  # half-way along the collapsed arc
    assert not np.any(np.isclose(on_rim[:, 0], 5.0) | np.isclose(on_rim[:, 0], 5.2))


def test_a_short_boundary_arc_between_two_corners_keeps_its_segment():
    # A 0.28-long chamfer is as short, but both its ends are corners of the part: no
    # collapse may move one of them.
    domain = domain_from_json({"loops": [polygon([[0, 0], [10, 0], [10, 3.8], [9.8, 4],
                                                  [0, 4]])]})
    partition = build_partition(domain, [_vertical(5.0, True, 3, 9.8)], 1.0)
    chamfer = [e for e, edge in enumerate(partition.edges)
               if edge.is_boundary and edge.length < 0.5]
    assert len(chamfer) == 1
    edge = partition.edges[chamfer[0]]
    assert edge.a in partition.fixed and edge.b in partition.fixed
    assert quantize(partition, 1.0)[chamfer[0]] >= 1


def _elongated_hexagon():
    return domain_from_json({"loops": [polygon([[0, 0], [4, 0], [5, 1.5], [4, 3], [0, 3],
                                                [-1, 1.5]])]})


def test_a_six_cornered_face_is_a_free_face_unless_cuts_are_asked_for():
    partition = build_partition(_elongated_hexagon(), [], 1.0)
    assert not partition.blocks and len(partition.free_faces) == 1
    assert "has 6 corners" in partition.free_faces[0].reason


def test_a_six_cornered_face_is_cut_where_the_cut_leaves_the_widest_angles():
    # Of the three cuts between opposite corners, the one across the middle leaves 56°
    # either side at both its ends; the diagonals leave 37°.
    domain = _elongated_hexagon()
    partition = build_partition(domain, [], 1.0, last_resort=True)
    assert len(partition.blocks) == 2 and not partition.free_faces
    inner = [edge for edge in partition.edges if not edge.is_boundary]
    assert len(inner) == 1
    ends = sorted(map(tuple, partition.vertices[[inner[0].a, inner[0].b]].round(9)))
    assert ends == [(-1.0, 1.5), (5.0, 1.5)]
    mesh = build_quad_mesh(domain, partition, quantize(partition, 1.0))
    assert scaled_jacobians(mesh.nodes, mesh.quads).min() > 0.5


def _lens(depth):
    """An arc over a three-segment floor whose two bends turn by atan(depth / 3)."""
    return domain_from_json({"loops": [[
        {"line": [[0, 0], [3, -depth]]}, {"line": [[3, -depth], [7, -depth]]},
        {"line": [[7, -depth], [10, 0]]}, {"arc": [[10, 0], [5, 3], [0, 0]]}]]})


def test_a_two_cornered_face_gets_its_sharpest_two_bends_as_corners():
    # Bends of 21.8° (over PROMOTED_TURN): one block, cornered at the arc's ends and
    # at the bends; bends of 11.3° are no corners, and the lens stays a free face.
    partition = build_partition(_lens(1.2), [], 1.0)
    assert len(partition.blocks) == 1 and not partition.free_faces
    corners = sorted(map(tuple, partition.vertices[list(partition.blocks[0].corners)]
                         .round(9)))
    assert corners == [(0.0, 0.0), (3.0, -1.2), (7.0, -1.2), (10.0, 0.0)]
    flat = build_partition(_lens(0.6), [], 1.0)
    assert not flat.blocks and "has 2 corners" in flat.free_faces[0].reason


def _l_shape():
    return domain_from_json({"loops": [polygon([[0, 0], [6, 0], [6, 3], [3, 3], [3, 6],
                                                [0, 6]])]})


def test_a_face_with_a_reflex_corner_is_split_round_a_centre_as_the_last_resort():
    # The L's reflex corner is a spoke's end, as the middles of the sides between two
    # convex corners are: five blocks, one per convex corner, and no side beside the
    # reflex corner cut.
    domain = _l_shape()
    plain = build_partition(domain, [], 1.0)
    assert not plain.blocks and "turns back" in plain.free_faces[0].reason
    partition = build_partition(domain, [], 1.0, last_resort=True)
    assert len(partition.blocks) == 5 and not partition.free_faces
    spokes = [edge for edge in partition.edges if not edge.is_boundary]
    ends = {tuple(partition.vertices[edge.b].round(9)) for edge in spokes}
    assert ends == {(3.0, 0.0), (6.0, 1.5), (3.0, 3.0), (1.5, 6.0), (0.0, 3.0)}
    mesh = build_quad_mesh(domain, partition, quantize(partition, 1.0))
    assert scaled_jacobians(mesh.nodes, mesh.quads).min() > 0.3


def test_two_reflex_corners_side_by_side_leave_the_face_free():
    # A U: its two reflex corners at the slot's floor are one side apart, so no block
    # would have a convex corner between them.
    domain = domain_from_json({"loops": [polygon([[0, 0], [6, 0], [6, 6], [4, 6], [4, 2],
                                                  [2, 2], [2, 6], [0, 6]])]})
    partition = build_partition(domain, [], 1.0, last_resort=True)
    assert not partition.blocks and len(partition.free_faces) == 1


def test_a_seven_cornered_face_is_split_round_a_centre_as_the_last_resort():
    angles = 2 * np.pi * np.arange(7) / 7
    domain = domain_from_json({"loops": [polygon(np.column_stack(
        [5 * np.cos(angles), 5 * np.sin(angles)]).tolist())]})
    assert "has 7 corners" in build_partition(domain, [], 1.0).free_faces[0].reason
    partition = build_partition(domain, [], 1.0, last_resort=True)
    assert len(partition.blocks) == 7 and not partition.free_faces
    mesh = build_quad_mesh(domain, partition, quantize(partition, 1.0))
    assert scaled_jacobians(mesh.nodes, mesh.quads).min() > 0.3


def test_boundary_edges_are_measured_along_their_curves():
    # Chords of the sampled arc are shorter by up to 1e-5 of an element, and by other
    # amounts in a mirrored copy (whose samples run the other way round): enough to
    # reorder near-equal arcs in the segment-count program's tie-break order.
    import math

    domain = domain_from_json({"loops": [[
        {"line": [[0, 0], [10, 0]]}, {"line": [[10, 0], [10, 3]]},
        {"arc": [[10, 3], [10 - 1 + math.cos(math.pi / 4), 3 + math.sin(math.pi / 4)],
                 [9, 4]]},
        {"line": [[9, 4], [0, 4]]}, {"line": [[0, 4], [0, 0]]}]]})
    partition = build_partition(domain, [_vertical(5.0, True, 3, 9.0)], 1.0)
    (arc,) = [edge for edge in partition.edges if edge.is_boundary
              and any(domain.loops[0][p.segment].kind == "arc" for p in edge.pieces)]
    chords = float(np.hypot(*np.diff(arc.points, axis=0).T).sum())
    assert arc.length == pytest.approx(math.pi / 2, abs=1e-12)
    assert chords < arc.length


def test_the_share_of_the_area_in_blocks_is_what_the_free_faces_leave():
    # The hexagon cut in two: both blocks, one, none (free_blocks), and the share of the
    # area in blocks that ranks a rebuild against the mesh in hand (rounds._rounds).
    domain = _elongated_hexagon()
    partition = build_partition(domain, [], 1.0, last_resort=True)
    assert block_area_share(partition, domain.area) == pytest.approx(1.0)
    assert block_area_share(free_blocks(partition, [0, 1], "test"),
                            domain.area) == pytest.approx(0.0, abs=1e-12)
    # The cut runs across the middle: each block holds half the hexagon.
    assert block_area_share(free_blocks(partition, [0], "test"),
                            domain.area) == pytest.approx(0.5)
    # A face with holes: the holes' area is no face's.
    plate = domain_from_json({"loops": [polygon([[0, 0], [10, 0], [10, 10], [0, 10]]),
                                        polygon([[4, 6], [6, 6], [6, 4], [4, 4]])]})
    whole = build_partition(plate, [], 1.0)
    assert whole.free_faces and not whole.blocks
    assert block_area_share(whole, plate.area) == pytest.approx(0.0, abs=1e-12)


def _clamp_end():
    """A crescent: an arc from (0, 8) back to (0, 0) bowing in to x = 3, and round it
    a polyline whose four bends all turn by 45°, two at each end."""
    return domain_from_json({"loops": [[
        {"line": [[0, 0], [2, 0]]}, {"line": [[2, 0], [4, 2]]}, {"line": [[4, 2], [4, 6]]},
        {"line": [[4, 6], [2, 8]]}, {"line": [[2, 8], [0, 8]]},
        {"arc": [[0, 8], [3, 4], [0, 0]]}]]})


def test_of_tied_bends_a_two_cornered_face_takes_the_pair_that_balances_its_sides():
    # Four bends of exactly 45° tie for the two corners the crescent lacks (held-out
    # fsr-dance-pad sensor-assembly f343, a C-shaped clamp: eight such chamfer corners,
    # no block at either size, 18 and 46 irregular vertices from gmsh).  The tie left the
    # face free; the pair whose block has its opposite sides nearest in length is the
    # two bends next to the tips (sides 2 and 2, 9.7 and the arc's 9.9), the ends a
    # clamp's band has.
    partition = build_partition(_clamp_end(), [], 1.0)
    assert len(partition.blocks) == 1 and not partition.free_faces
    corners = sorted(map(tuple, partition.vertices[list(partition.blocks[0].corners)]
                         .round(9)))
    assert corners == [(0.0, 0.0), (0.0, 8.0), (2.0, 0.0), (2.0, 8.0)]



@pytest.mark.parametrize("mirrored", [False, True])
def test_an_outline_that_leaves_a_vertex_the_way_it_came_turns_as_its_far_ends_say(
        mirrored):
    # A line running on along a boundary's flat and then parting from it (held-out
    # sensor-assembly f89: lines from a slot's end along its flat top): the face between
    # turns by exactly pi or -pi there, and round-off chose which, so one of two such
    # faces was a block and its mirror image's was not.  The far ends decide: a face
    # squeezed between the two (the boundary bends away from the line on the face's
    # side) has a corner of no angle (pi); one the other side turns back (-pi).
    from quadcnn_wb.core.layout.partition import _turn_back

    line = np.array([[2.0, 0.0], [1.0, 0.0], [0.0, 0.0]])  # arriving at the vertex
    away = np.array([[0.0, 0.0], [0.5, 0.0], [1.0, -0.3], [1.5, -1.0]])
    back = away * [1.0, -1.0]
    flip = np.array([-1.0, 1.0])
    for leaving, turn in ((away, np.pi), (back, -np.pi)):
        if mirrored:  # the mirror image runs round the face the other way
            arriving, leaving = (leaving * flip)[::-1], (line * flip)[::-1]
        else:
            arriving = line
        d_in = arriving[-1] - arriving[-2]
        assert _turn_back(arriving, leaving, d_in / np.hypot(*d_in)) == turn
