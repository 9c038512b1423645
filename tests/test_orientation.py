"""Quads of a block are turned counter-clockwise together: one its map lays inverted stays
inverted (for smoothing to mend, and for the checks to see), not turned on its own."""

from __future__ import annotations

import numpy as np

from quadcnn_wb.core.mesh.orientation import counter_clockwise_quads, signed_areas
from quadcnn_wb.core.mesh.quadmesh import _turned_by_block, scaled_jacobians


def strip(bulge: bool):
    """A block two quads across and three along, listed clockwise; with ``bulge`` its
    middle row pushed out past its far side over the middle quad, as a map whose short
    side bulges lays the middle row of a thin strip."""
    xs, ys = np.arange(4.0), np.array([0.0, 1.0, 2.0])
    nodes = np.array([[x, y] for y in ys for x in xs])
    if bulge:
        nodes[[5, 6], 1] = 2.5
    quads = np.array([[r * 4 + c, (r + 1) * 4 + c, (r + 1) * 4 + c + 1, r * 4 + c + 1]
                      for r in range(2) for c in range(3)])  # clockwise
    return nodes, quads


def test_a_block_is_turned_as_a_whole():
    nodes, quads = strip(False)
    turned = _turned_by_block(nodes, quads, np.zeros(6, int))
    assert (signed_areas(nodes, turned) > 0).all()


def test_a_quad_its_map_lays_inverted_stays_inverted():
    nodes, quads = strip(True)
    turned = _turned_by_block(nodes, quads, np.zeros(6, int))
    # The upper middle quad lies folded over; turned on its own it read as a fine
    # rectangle, with its block it reads as what it is.
    assert scaled_jacobians(nodes, turned)[4] < 0
    assert scaled_jacobians(nodes, turned)[:3].min() > 0
    assert scaled_jacobians(nodes, counter_clockwise_quads(nodes, quads))[4] > 0.9


def test_free_face_quads_are_turned_one_by_one():
    nodes, quads = strip(True)
    turned = _turned_by_block(nodes, quads, np.full(6, -1))
    assert (signed_areas(nodes, turned) >= 0).all()
