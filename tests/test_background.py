"""The gmsh background mesh: node target, orientation, exact boundary, corners, clean gmsh."""

from __future__ import annotations

import math

import gmsh
import numpy as np
import pytest
from conftest import circle, rect

from quadcnn_wb.core.field.background import background_mesh
from quadcnn_wb.core.input.curves import winding_number, winding_numbers
from quadcnn_wb.core.input.domain import domain_from_json
from quadcnn_wb.core.input.load import load_domain

EXPECTED_CORNERS = {  # interior angles in degrees, sorted
    "concave": [90] * 6 + [270] * 2,
    "four_hole": [90] * 4,
    "l_shape": [90] * 5 + [270],
    "plate_hole": [90] * 4,
    "semicircle": [90, 90],
}


def signed_areas(mesh):
    a, b, c = (mesh.nodes[mesh.triangles[:, k]] for k in range(3))
    return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1])
                  - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))


@pytest.mark.parametrize("target", [500, 2048, 4000])
def test_node_count_within_five_percent(example_path, target):
    mesh = background_mesh(load_domain(example_path), nodes=target)
    assert abs(mesh.n_nodes - target) <= 0.05 * target


@pytest.mark.parametrize("loops", [
    [rect(10, 0.3)],  # thin strip: the count jumps a row at a time
    [rect(2, 1), circle(0.5, 0.5, 0.01)],  # hole far below the element size
    [circle(0, 0, 1e-6)],  # a 1 µm disk
    [circle(0, 0, 1e5), circle(3e4, 0, 5e4)],  # a 100 km part with an off-centre hole
    # bolt holes of 3 mm in a grid all over a plate: gmsh spread their sizes everywhere
    # and jumped from 150 to 4000 nodes
    [rect(200, 200)] + [circle(20 + 80 * i, 20 + 80 * j, 1.5)
                        for i in range(3) for j in range(3)],
    [rect(254, 264)] + [circle(20 + 53.5 * i, 20 + 112 * j, 1.6)
                        for i in range(5) for j in range(3)],
])
def test_node_count_on_awkward_shapes(loops):
    mesh = background_mesh(domain_from_json({"loops": loops}), nodes=2048)
    assert abs(mesh.n_nodes - 2048) <= 0.05 * 2048


def test_triangles_counter_clockwise_and_cover_the_domain(example_path):
    domain = load_domain(example_path)
    mesh = background_mesh(domain)
    areas = signed_areas(mesh)
    assert np.all(areas > 0)
    # Straight-sided triangles under-cover curved holes/arcs only slightly.
    assert areas.sum() == pytest.approx(domain.area, rel=5e-3)
    assert len(np.unique(mesh.triangles)) == mesh.n_nodes  # no orphan nodes


def test_boundary_nodes_lie_exactly_on_their_curves(example_path):
    domain = load_domain(example_path)
    mesh = background_mesh(domain)
    for node, li, si, t in zip(mesh.boundary_nodes, mesh.boundary_loop,
                               mesh.boundary_segment, mesh.boundary_param):
        curve = domain.loops[li][si]
        assert np.array_equal(mesh.nodes[node], curve.point(t))
        if curve.kind != "line":
            dist = math.hypot(*(mesh.nodes[node] - curve.center))
            assert abs(dist - curve.radius) <= 4e-16 * domain.size


def test_boundary_is_every_boundary_edge_in_loop_order(example_path):
    mesh = background_mesh(load_domain(example_path))
    edges = np.sort(np.concatenate([mesh.triangles[:, [0, 1]], mesh.triangles[:, [1, 2]],
                                    mesh.triangles[:, [2, 0]]]), axis=1)
    uniq, counts = np.unique(edges, axis=0, return_counts=True)
    free = {tuple(e) for e in uniq[counts == 1]}
    walked = set()
    for li in np.unique(mesh.boundary_loop):
        ids = mesh.boundary_nodes[mesh.boundary_loop == li]
        for a, b in zip(ids, np.roll(ids, -1)):
            walked.add((min(a, b), max(a, b)))
    assert walked == free
    assert len(np.unique(mesh.boundary_nodes)) == len(mesh.boundary_nodes)


def test_tangents_are_unit_with_the_domain_on_their_left(example_path):
    domain = load_domain(example_path)
    mesh = background_mesh(domain)
    assert np.allclose(np.hypot(*mesh.boundary_tangent.T), 1.0, atol=1e-14)
    step = 1e-4 * domain.size
    corners = set(mesh.corner_nodes.tolist())
    for node, tangent in zip(mesh.boundary_nodes, mesh.boundary_tangent):
        if node in corners:  # stepping left from a corner runs along the other edge
            continue
        left = mesh.nodes[node] + step * np.array([-tangent[1], tangent[0]])
        inside = winding_number(domain.loops[0], left) != 0 and all(
            winding_number(hole, left) == 0 for hole in domain.loops[1:])
        assert inside


def test_winding_numbers_of_many_points_match_one_by_one(example_path):
    """The batched test the label walks use agrees with the scalar one, arcs included."""
    domain = load_domain(example_path)
    corners = np.array([c.p0 for loop in domain.loops for c in loop])
    lo, hi = corners.min(axis=0) - domain.size, corners.max(axis=0) + domain.size
    points = np.random.default_rng(3).uniform(lo, hi, size=(500, 2))
    for loop in domain.loops:
        one_by_one = [winding_number(loop, p) for p in points]
        assert np.array_equal(winding_numbers(loop, points), one_by_one)


def test_corners_and_their_interior_angles(example_path):
    domain = load_domain(example_path)
    mesh = background_mesh(domain)
    degrees = sorted(round(float(np.degrees(a)), 9) for a in mesh.corner_angles)
    assert degrees == EXPECTED_CORNERS[example_path.stem]
    vertices = {tuple(c.p0) for loop in domain.loops for c in loop if c.kind != "circle"}
    for node in mesh.corner_nodes:
        assert tuple(mesh.nodes[node]) in vertices


def test_smooth_joints_are_not_corners():
    # A rounded slot: two half circles joined tangentially to two lines.
    loop = [{"line": [[0, 0], [2, 0]]}, {"arc": [[2, 0], [3, 1], [2, 2]]},
            {"line": [[2, 2], [0, 2]]}, {"arc": [[0, 2], [-1, 1], [0, 0]]}]
    mesh = background_mesh(domain_from_json({"loops": [loop]}))
    assert len(mesh.corner_nodes) == 0


def test_same_input_gives_the_same_mesh():
    domain = domain_from_json({"loops": [rect(2, 1), circle(0.7, 0.4, 0.2)]})
    a, b = background_mesh(domain), background_mesh(domain)
    assert np.array_equal(a.nodes, b.nodes) and np.array_equal(a.triangles, b.triangles)


def test_scaled_and_moved_input_gives_the_scaled_mesh():
    base = domain_from_json({"loops": [rect(2, 1), circle(0.7, 0.4, 0.2)]})
    moved = domain_from_json({"loops": [rect(2e3, 1e3, 5e4, -3e4),
                                        circle(5e4 + 700, -3e4 + 400, 200)]})
    a, b = background_mesh(base), background_mesh(moved)
    assert len(a.nodes) == len(b.nodes) and np.array_equal(a.triangles, b.triangles)
    assert np.allclose((b.nodes - [5e4, -3e4]) / 1e3, a.nodes, atol=1e-9)


def test_gmsh_is_left_as_found_and_quiet(capfd):
    domain = load_domain_from_rect()
    assert not gmsh.isInitialized()
    background_mesh(domain)
    assert not gmsh.isInitialized()
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("users_model")
        gmsh.option.setNumber("General.NumThreads", 3)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.123)
        background_mesh(domain)
        assert gmsh.isInitialized()
        assert gmsh.model.getCurrent() == "users_model"
        assert gmsh.option.getNumber("General.NumThreads") == 3
        assert gmsh.option.getNumber("Mesh.MeshSizeMax") == 0.123
    finally:
        gmsh.finalize()
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def load_domain_from_rect():
    return domain_from_json({"loops": [rect(3, 1)]})
