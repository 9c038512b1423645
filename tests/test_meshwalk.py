"""Point location decides inside or out well above round-off: a trace that runs along a
boundary edge must not leave the domain in one copy of a part and stay in another."""

from __future__ import annotations

import numpy as np

from quadcnn_wb.core.field.meshwalk import INSIDE_TOL, MeshWalker

SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
TRIANGLES = np.array([[0, 1, 2], [0, 2, 3]])


def _locate(points, scale=1.0):
    walker = MeshWalker(SQUARE * scale, TRIANGLES)
    points = np.asarray(points, dtype=float) * scale
    return walker.locate(np.ones(len(points), dtype=np.int64), points)


def test_a_point_a_last_bit_outside_a_boundary_edge_is_inside():
    # 1e-11 of the mesh below its bottom edge: what a coordinate rounded one way in one
    # copy and the other way in another puts there (the old walk, 1e-12 in barycentric
    # terms, walked it out).
    tri, bary, exit_edge = _locate([[0.5, -1e-11], [0.9, -1e-11]])
    assert (tri == 0).all() and (exit_edge == -1).all()
    assert np.allclose(bary.sum(axis=1), 1.0)


def test_a_point_really_outside_walks_out_through_the_edge_it_crossed():
    tri, _, exit_edge = _locate([[0.5, -1e-6], [-1e-6, 0.5]])
    assert (tri == -1).all()
    # the bottom edge is triangle 0's side opposite its vertex 2; the left one, triangle
    # 1's side opposite its vertex 1
    assert exit_edge.tolist() == [[0, 2], [1, 1]]


def test_the_tolerance_is_relative_to_the_mesh():
    for scale in (1e-3, 1.0, 1e3):
        inside, _, _ = _locate([[0.5, -0.1 * INSIDE_TOL]], scale)
        outside, _, _ = _locate([[0.5, -10.0 * INSIDE_TOL * np.sqrt(2.0)]], scale)
        assert inside.tolist() == [0] and outside.tolist() == [-1]
