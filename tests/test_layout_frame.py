"""The pipeline runs in the part's frame (core.layout_frame): a turned or rescaled copy is
meshed from the same numbers, so it gets the very same quads, node for node, and nodes
that are the original's moved; boundary nodes lie on the input's own curves and corner
nodes are its vertices, to the bit."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from quadcnn_wb.core.input.domain import domain_from_json
from quadcnn_wb.core.input.load import load_domain
from quadcnn_wb.core.input.transform import similarity, transform_domain_json
from quadcnn_wb.core.layout_frame import frame_of, framed_domain, on_exact_curves
from quadcnn_wb.core.pipeline import mesh_domain

CORPUS = Path(__file__).parent / "corpus"


@pytest.mark.parametrize("file", ["io1_flange.brep", "sketch_keyhole_plate.brep"])
@pytest.mark.parametrize("degrees, scale", [(37.0, 1.0), (131.0, 1e-3), (73.0, 1e3)])
def test_a_turned_copy_gets_the_same_quads_node_for_node(file, degrees, scale):
    data = load_domain(CORPUS / file).to_json()
    base = mesh_domain(domain_from_json(data))
    matrix, shift = similarity(degrees, scale), np.array([3.0, -2.0])
    turned = mesh_domain(domain_from_json(transform_domain_json(data, matrix, shift)))
    assert np.array_equal(turned.mesh.quads, base.mesh.quads)
    assert np.array_equal(turned.mesh.block_of_quad, base.mesh.block_of_quad)
    assert turned.quality == base.quality  # found in the frame: the same to the bit
    expected = base.mesh.nodes @ matrix.T + shift
    size = base.domain.size * scale
    assert np.abs(turned.mesh.nodes - expected).max() <= 1e-9 * size


def test_boundary_nodes_are_on_the_given_curves_and_corners_are_its_vertices():
    data = load_domain(CORPUS / "sketch_keyhole_plate.brep").to_json()
    domain = domain_from_json(transform_domain_json(data, similarity(37.0, 7.0), [1e3, 5.0]))
    result = mesh_domain(domain)
    nodes = result.mesh.nodes
    on = np.nonzero(result.mesh.boundary)[0]
    gaps = [min(np.hypot(*(c.point(c.project(nodes[n])) - nodes[n]))
                for loop in domain.loops for c in loop) for n in on]
    assert max(gaps) <= 1e-12 * domain.size
    vertices = {tuple(c.p0) for loop in domain.loops for c in loop
                if not (c.kind == "circle")}
    exact = {tuple(p) for p in nodes[on]}
    assert vertices <= exact  # every loop vertex is a node, bit for bit


def test_the_frame_is_the_same_numbers_for_every_turned_copy():
    data = load_domain(CORPUS / "io1_flange.brep").to_json()
    original = domain_from_json(data)
    turned = domain_from_json(transform_domain_json(data, similarity(211.0, 1e3), [7.0, 9.0]))
    a, b = (framed_domain(d, frame_of(d)) for d in (original, turned))
    for la, lb in zip(a.loops, b.loops):
        for ca, cb in zip(la, lb):
            assert np.array_equal(ca.p0, cb.p0) and np.array_equal(ca.p1, cb.p1)


def test_nodes_off_a_curve_by_round_off_are_put_on_it():
    domain = domain_from_json({"loops": [[{"line": [[0, 0], [4, 0]]},
                                          {"line": [[4, 0], [4, 3]]},
                                          {"line": [[4, 3], [0, 3]]},
                                          {"line": [[0, 3], [0, 0]]}],
                                         [{"circle": {"center": [2, 1.5], "radius": 0.5}}]]})
    noisy = np.array([[4.0 + 1e-13, 3.0 - 1e-13], [2.0, 1e-12], [2.5 + 1e-13, 1.5]])
    fixed = on_exact_curves(domain, noisy)
    assert fixed[0].tolist() == [4.0, 3.0]  # the vertex itself
    assert fixed[1].tolist() == [2.0, 0.0]
    assert abs(np.hypot(*(fixed[2] - [2.0, 1.5])) - 0.5) <= 1e-15
