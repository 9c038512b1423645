"""Splitting a face of the partition round a centre (layout.subdivide): the spokes must
stay inside the face, also where a side bulges in without a reflex corner."""

from __future__ import annotations

import numpy as np

from quadcnn_wb.core.layout.face_geometry import segment_inside
from quadcnn_wb.core.layout.partition_types import Edge
from quadcnn_wb.core.layout.subdivide import split_odd_faces


def _bulging_pentagon():
    """Five corners, counter-clockwise; the side from the last corner back to the first
    bulges deep into the face (a boundary curve seen from inside), so the mean of the
    corners and side middles lies beyond it, outside the face."""
    corners = [np.array(p, dtype=float) for p in ((0, 0), (4, 0), (4, 3), (2, 4), (0, 3))]
    edges = []
    for a in range(5):
        b = (a + 1) % 5
        if b == 0:  # corner 4 -> corner 0, bulging in to x = 2.8 half-way
            t = np.linspace(0.0, 1.0, 41)
            points = np.column_stack([2.8 * np.sin(np.pi * t), 3.0 * (1.0 - t)])
        else:
            points = np.linspace(corners[a], corners[b], 9)
        edges.append(Edge(points=points, a=a, b=b))
    sides = [[(e, True)] for e in range(5)]
    return corners, edges, sides


def test_a_face_whose_side_bulges_in_gets_its_centre_where_every_spoke_stays_inside():
    vertices, edges, sides = _bulging_pentagon()
    outline = np.vstack([edge.points[:-1] for edge in edges])
    naive = np.mean(vertices + [edge.points[len(edge.points) // 2] for edge in edges], axis=0)
    assert not segment_inside(outline, naive, vertices[2])  # what the mean centre would do
    edges_out = list(edges)
    vertices_out, blocks, free = split_odd_faces(vertices, edges_out, [(list(range(5)),
                                                  sides, ())], [], None)
    assert len(blocks) == 5 and not free
    centre_id = len(vertices_out) - 1
    spokes = [edge for edge in edges_out if edge.a == centre_id]
    assert len(spokes) == 5
    for spoke in spokes:
        assert segment_inside(outline, spoke.points[0], spoke.points[-1])


def _two_triangles_on_one_line():
    """Two three-cornered faces either side of the line P-Q: the upper one's side is P-Q
    alone, the lower one's runs on from Q to R, a little further along the line.  Split
    first, the upper face puts a vertex in the middle of P-Q, close enough to the lower
    side's own middle to be taken for it; split first, the lower face puts its middle at
    x = 1.15, where the upper side then takes it."""
    points = [(0, 0), (2, 0), (2.3, 0), (1.15, -2), (1, 2)]  # P Q R S T
    vertices = [np.array(p, dtype=float) for p in points]
    ends = [(0, 1), (1, 2), (1, 4), (4, 0), (0, 3), (3, 2)]  # e f g h i j
    edges = [Edge(points=np.linspace(vertices[a], vertices[b], 9), a=a, b=b)
             for a, b in ends]
    upper = ((0, 1, 4), [[(0, True)], [(2, True)], [(3, True)]], ())
    lower = ((2, 0, 3), [[(1, False), (0, False)], [(4, True)], [(5, True)]], ())
    return vertices, edges, upper, lower


def test_odd_faces_are_split_in_an_order_of_their_places_not_of_their_numbers():
    # A mirror image numbers the faces the other way round (nist_ctc02_logo_plate at
    # diameter/100: one middle moved by a tenth of an element, and the counts with it).
    made = []
    for flip in (False, True):
        vertices, edges, upper, lower = _two_triangles_on_one_line()
        faces = [lower, upper] if flip else [upper, lower]
        out, blocks, free = split_odd_faces(vertices, edges, faces, [], None)
        assert len(blocks) == 6 and not free
        made.append(sorted(np.round(np.asarray(out[len(vertices):]), 9).tolist()))
    assert made[0] == made[1]
