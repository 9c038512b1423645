"""Boundary nodes slid together along arcs that get no segments (quadmesh._place_slid_nodes)
sit half-way along the whole run of those arcs: a place that moves as little as the
geometry does, where the middle of the longest arc jumped between two arcs of one length
as round-off had them (nist_ctc01_logo_bracket moved by 1e4 of its size: the node a
fifth of an element away, a free face beside it unfillable, another mesh)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from shapes import rect

from quadcnn_wb.core.input.domain import domain_from_json
from quadcnn_wb.core.layout.partition_types import BoundaryPiece, Edge
from quadcnn_wb.core.mesh.quadmesh import _middle_of_run

SQUARE = domain_from_json({"loops": [rect(4, 4)]})


def _bottom_edge(a: int, b: int, x0: float, x1: float) -> Edge:
    """An edge along the square's bottom side (loop 0, curve 0, from (0, 0) to (4, 0))
    from x0 to x1, between partition vertices a and b."""
    return Edge(points=np.array([[x0, 0.0], [x1, 0.0]]), a=a, b=b,
                pieces=(BoundaryPiece(0, 0, x0 / 4.0, x1 / 4.0),), exact_length=abs(x1 - x0))


@pytest.mark.parametrize("wobble", [-1e-13, 0.0, 1e-13])
@pytest.mark.parametrize("order", [(0, 1), (1, 0)])
def test_two_arcs_of_one_length_put_the_node_on_their_shared_end(wobble, order):
    assert tuple(SQUARE.loops[0][0].p0) == (0.0, 0.0)  # the bottom side runs along +x
    edges = [_bottom_edge(0, 1, 1.0, 2.0), _bottom_edge(1, 2, 2.0, 3.0 + wobble)]
    middle = _middle_of_run(SQUARE, SimpleNamespace(edges=edges), list(order))
    assert np.allclose(middle, [2.0, 0.0], atol=1e-9)


def test_a_run_walked_against_its_edges_has_the_same_middle():
    edges = [_bottom_edge(1, 0, 2.0, 1.0), _bottom_edge(2, 1, 3.5, 2.0)]
    middle = _middle_of_run(SQUARE, SimpleNamespace(edges=edges), [0, 1])
    assert np.allclose(middle, [2.25, 0.0], atol=1e-12)
