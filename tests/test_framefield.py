"""Cross field and singular points: alignment, unit frames, exactly the minimal singularities."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from conftest import SHARED_EXAMPLES
from shapes import OWN_SHAPES, rotation, transform_domain

from quadcnn_wb.core.field.background import background_mesh
from quadcnn_wb.core.field.framefield import compute_frame_field
from quadcnn_wb.core.input.corners import corner_quads, nearest_quarters
from quadcnn_wb.core.input.domain import domain_from_json
from quadcnn_wb.core.input.load import load_domain

EXPECTED = json.loads((SHARED_EXAMPLES / "expected_singularities.json").read_text())


def field_of(domain, nodes=2048):
    mesh = background_mesh(domain, nodes=nodes)
    return mesh, compute_frame_field(mesh)


def poincare_hopf_holds(mesh, field, holes) -> bool:
    total = sum((4 - s.valence) / 4 for s in field.singularities)
    total += sum((2 - nearest_quarters(a)) / 4 for a in mesh.corner_angles)
    return abs(total - (1 - holes)) < 1e-9


def test_shared_examples_have_exactly_the_expected_singularities(example_path):
    domain = load_domain(example_path)
    mesh, field = field_of(domain)
    expected = EXPECTED[example_path.stem]
    assert field.valences() == {3: expected["val3"], 5: expected["val5"]}
    assert poincare_hopf_holds(mesh, field, domain.holes)


@pytest.mark.parametrize("name", OWN_SHAPES)
def test_own_shapes_have_the_minimal_singularities(name):
    loops, val3, val5 = OWN_SHAPES[name]
    domain = domain_from_json({"loops": loops})
    mesh, field = field_of(domain)
    assert field.valences() == {3: val3, 5: val5}
    assert poincare_hopf_holds(mesh, field, domain.holes)


@pytest.mark.parametrize("matrix", [rotation(30), rotation(-117, scale=1e3),
                                    rotation(0, mirror=True), rotation(71, 1e-4, mirror=True)],
                         ids=["rotated", "rotated+scaled", "mirrored", "all"])
@pytest.mark.parametrize("name", ["four_hole", "semicircle", "concave", "plate_hole"])
def test_counts_survive_rotation_scaling_and_mirroring(name, matrix):
    data = json.loads((SHARED_EXAMPLES / f"{name}.json").read_text())
    moved = domain_from_json(transform_domain(data, matrix, shift=(123.0, -45.0)))
    _, field = field_of(moved)
    assert field.valences() == {3: EXPECTED[name]["val3"], 5: EXPECTED[name]["val5"]}


@pytest.mark.parametrize("matrix", [rotation(37), rotation(131, 1e-3, mirror=True)],
                         ids=["turned", "turned+scaled+mirrored"])
@pytest.mark.parametrize("name", ["chamfered plate", "plate with a 45° step"])
def test_corners_at_a_tie_wind_the_same_in_every_pose(name, matrix):
    loops, val3, val5 = OWN_SHAPES[name]
    moved = domain_from_json(transform_domain({"loops": loops}, matrix, shift=(1e3, -7.0)))
    mesh, field = field_of(moved)
    assert field.valences() == {3: val3, 5: val5}
    assert poincare_hopf_holds(mesh, field, moved.holes)


def test_a_corner_angle_at_a_tie_is_the_tie_whatever_the_round_off():
    quarter = math.pi / 2
    for wobble in (-1e-12, 0.0, 1e-12):
        assert corner_quads(1.5 * quarter + wobble) == 2  # 135°: flat
        assert corner_quads(2.5 * quarter + wobble) == 2  # 225°: flat
        assert corner_quads(3.5 * quarter + wobble) == 4
        assert corner_quads(0.5 * quarter + wobble) == 1  # never no quad
    assert corner_quads(math.radians(134)) == 1 and corner_quads(math.radians(136)) == 2
    assert corner_quads(math.radians(224)) == 2 and corner_quads(math.radians(226)) == 3
    # a cusp (tangent arcs) gets its one quad, but the field turns there as on a smooth
    # stretch (crank_arm_web's 1.4° cusps: a cross turned a quarter there lost every block)
    assert corner_quads(math.radians(1.4)) == 1 and nearest_quarters(math.radians(1.4)) == 0


def test_frames_are_unit_and_perpendicular(example_path):
    _, field = field_of(load_domain(example_path))
    f = field.frames
    assert np.allclose(np.hypot(f[:, 0], f[:, 1]), 1.0, atol=1e-14)
    assert np.allclose(np.hypot(f[:, 2], f[:, 3]), 1.0, atol=1e-14)
    assert np.allclose(f[:, 0] * f[:, 2] + f[:, 1] * f[:, 3], 0.0, atol=1e-14)


def test_field_is_aligned_with_the_boundary(example_path):
    mesh, field = field_of(load_domain(example_path))
    f = field.frames[mesh.boundary_nodes]
    t = mesh.boundary_tangent
    # One of the two frame vectors is parallel to the tangent (the other is then normal).
    off = np.minimum(np.abs(f[:, 0] * t[:, 1] - f[:, 1] * t[:, 0]),
                     np.abs(f[:, 2] * t[:, 1] - f[:, 3] * t[:, 0]))
    assert off.max() < 1e-9
    # Right-angle corners hold both of their edges exactly.
    position = {int(n): k for k, n in enumerate(mesh.boundary_nodes)}
    for node, t_in in zip(mesh.corner_nodes, mesh.corner_tangents_in):
        v = field.frames[node]
        assert min(abs(v[0] * t_in[1] - v[1] * t_in[0]),
                   abs(v[2] * t_in[1] - v[3] * t_in[0])) < 1e-9, position[int(node)]


def test_singular_points_lie_in_their_triangle_with_spread_directions(example_path):
    mesh, field = field_of(load_domain(example_path))
    for s in field.singularities:
        a, b, c = mesh.nodes[mesh.triangles[s.triangle]]
        u, v = np.linalg.solve(np.array([b - a, c - a]).T, s.xy - a)
        assert u >= -1e-9 and v >= -1e-9 and u + v <= 1 + 1e-9
        assert len(s.directions) == s.valence
        angles = np.sort(np.arctan2(s.directions[:, 1], s.directions[:, 0]))
        gaps = np.diff(np.concatenate([angles, [angles[0] + 2 * math.pi]]))
        assert gaps.min() > math.radians(30)  # 3 or 5 distinct directions, not a cluster


def test_concave_corners_are_streamline_sources():
    for name, count in (("l_shape", 1), ("concave", 2), ("four_hole", 0)):
        _, field = field_of(load_domain(SHARED_EXAMPLES / f"{name}.json"))
        assert len(field.corner_sources) == count
        for source in field.corner_sources:
            assert source.angle == pytest.approx(1.5 * math.pi)
            assert len(source.directions) == 2


def test_field_is_deterministic():
    domain = load_domain(SHARED_EXAMPLES / "four_hole.json")
    (_, f1), (_, f2) = field_of(domain), field_of(domain)
    assert np.array_equal(f1.z, f2.z)
    assert [s.xy.tolist() for s in f1.singularities] == [s.xy.tolist() for s in f2.singularities]


def test_a_zero_outside_its_triangle_goes_to_the_nearest_point_whatever_the_corner_order():
    # The clamp used to clip barycentric coordinates measured from the first corner: a
    # mirrored copy, whose triangles list their corners the other way round, got its
    # singular point up to a third of an element elsewhere (sketch_bracket).
    from itertools import permutations

    from quadcnn_wb.core.field.framefield import _clamp_into_triangle

    rng = np.random.default_rng(3)
    for _ in range(50):
        corners = rng.uniform(-1, 1, (3, 2))
        p = rng.uniform(-3, 3, 2)
        places = [_clamp_into_triangle(p, corners[list(order)])
                  for order in permutations(range(3))]
        assert all(np.allclose(q, places[0], atol=1e-12) for q in places)
        u, v = rng.uniform(0, 1, (2, 400))
        u, v = np.where(u + v > 1, 1 - u, u), np.where(u + v > 1, 1 - v, v)
        inside = corners[0] + np.outer(u, corners[1] - corners[0]) \
            + np.outer(v, corners[2] - corners[0])
        assert np.hypot(*(p - places[0])) <= np.hypot(*(inside - p).T).min() + 1e-12


def twin_bore(d, r=1.5):
    """A hole made of two overlapping disks of radius r, centres 2d apart: a loop of two
    arcs meeting at two sharp corners (26.5° at d = 1.46, 37.6° at d = 1.42), as where
    two bores of a pulley guard plate overlap."""
    h = math.sqrt(r * r - d * d)
    top, bottom = [0.0, h], [0.0, -h]
    return [{"arc": [top, [d + r, 0.0], bottom]}, {"arc": [bottom, [-d - r, 0.0], top]}]


@pytest.mark.parametrize("d", [1.42, 1.46])
def test_sharp_corners_between_two_bores_are_one_quad_corners(d):
    """The cross turns the long way round a lone corner of 22.5-45° (one quad's worth):
    read the short way, as a cusp, each corner had a valence-3 point beside it, with a
    valence-5 to answer it, and free faces between (share 0.96, 18 irregular vertices,
    worst scaled Jacobian 0.26-0.35)."""
    from shapes import rect

    from quadcnn_wb.core.pipeline import mesh_domain

    loops = [rect(10, 6, -5, -3), twin_bore(d)]
    result = mesh_domain(domain_from_json({"loops": loops}))
    q = result.quality
    assert result.structured_share == 1.0, result.problem
    assert sorted(s.valence for s in result.reference.field.singularities) == [5] * 6
    assert q["irregular_vertices"] == 6 and q["min_scaled_jacobian"] > 0.6
    moved = mesh_domain(domain_from_json(transform_domain(
        {"loops": loops}, rotation(211, 1e3, mirror=True), shift=(1e4, 3.0)))).quality
    assert (moved["quads"], moved["irregular_vertices"]) == (q["quads"], 6)


def test_a_sharp_corner_the_field_cannot_turn_the_long_way_stays_a_cusp():
    """A 40° corner of a trapezoid with a hole: the long way round leaves a zero in the
    corner's own triangle that nothing answers, so the corner is read as a cusp (short
    way; only the hole's four valence-5 points)."""
    from shapes import circle, polygon

    from quadcnn_wb.core.input.pose import canonical_pose

    tip = 3 / math.tan(math.radians(40))
    domain = domain_from_json({"loops": [polygon([[0, 0], [8, 0], [8, 3], [tip, 3]]),
                                         circle(6, 1.5, 0.8)]})
    field = compute_frame_field(background_mesh(domain, 2048), canonical_pose(domain))
    assert sorted(s.valence for s in field.singularities) == [5, 5, 5, 5]


def test_a_joint_that_is_no_corner_sets_the_field_alike_in_a_mirror_image():
    # A plate with a rounded corner whose arc leaves its lines at kinks of about 1e-6
    # rad (under CORNER_MIN_TURN: no corners), as CAD files keep tangent curves.  A
    # joint's tangent was the leaving curve's, which a mirror image (its loop run the
    # other way) takes from the other curve: held-out sensor-assembly f164's mirrored
    # copy had a pair of singular points more at diameter/100 (51 blocks against 55).
    # The mean of the two is the same both ways.
    from scipy.spatial import cKDTree

    from quadcnn_wb.core.field.reference import numerical_reference
    from quadcnn_wb.core.input.domain import domain_from_json
    from quadcnn_wb.core.input.transform import similarity, transform_domain_json

    bulge = 1.0 - math.sqrt(0.5) + 3e-7  # the arc's middle a little off the fillet's
    data = {"loops": [[{"line": [[0.0, 0.0], [10.0, 0.0]]}, {"line": [[10.0, 0.0], [10.0, 4.0]]},
                       {"line": [[10.0, 4.0], [1.0, 4.0]]},
                       {"arc": [[1.0, 4.0], [bulge, 4.0 - bulge], [0.0, 3.0]]},
                       {"line": [[0.0, 3.0], [0.0, 0.0]]}],
                      [{"circle": {"center": [6.0, 1.7], "radius": 0.8}}]]}
    mirrored = transform_domain_json(data, similarity(0.0, 1.0, True))
    given, image = (numerical_reference(domain_from_json(d), labels=False)
                    for d in (data, mirrored))
    gap, match = cKDTree(image.mesh.nodes).query(given.mesh.nodes * [-1.0, 1.0])
    assert gap.max() < 1e-6
    # A mirror turns a cross by -theta: z to its conjugate (4e-6 off before, at the
    # joints; the nodes' own round-off leaves a few 1e-8).
    assert np.abs(image.field.z[match] - np.conj(given.field.z)).max() < 1e-6


def _chamfered_square_fan():
    """A unit square with its top right corner cut by a chamfer one background edge
    long (two 135° corners), meshed as a fan round one interior node."""
    from quadcnn_wb.core.field.background import BackgroundMesh

    ring = np.array([[0, 0], [1, 0], [1, 0.9], [0.9, 1], [0, 1]], dtype=float)
    nodes = np.vstack([ring, [[0.45, 0.45]]])
    centre = len(ring)
    triangles = np.array([[k, (k + 1) % len(ring), centre] for k in range(len(ring))])
    tangents = np.array([ring[(k + 1) % len(ring)] - ring[k] for k in range(len(ring))])
    tangents /= np.hypot(*tangents.T)[:, None]
    arriving = np.roll(tangents, 1, axis=0)
    turns = np.arctan2(np.cross(arriving, tangents), (arriving * tangents).sum(axis=1))
    return BackgroundMesh(
        nodes=nodes, triangles=triangles, boundary_nodes=np.arange(len(ring)),
        boundary_loop=np.zeros(len(ring), dtype=int),
        boundary_segment=np.arange(len(ring)), boundary_param=np.zeros(len(ring)),
        boundary_tangent=tangents, corner_nodes=np.arange(len(ring)),
        corner_angles=np.pi - turns, corner_tangents_in=arriving, element_size=0.5)


def test_a_zero_on_a_boundary_edge_is_no_singular_point_whatever_the_round_off():
    """The chamfer's two 135° corners each hold their cross half-way through its turn,
    and both turn the same way, so the edge between them holds opposite z: the linear
    z is zero in the edge's middle, on the boundary, and the change along it is pi to
    round-off.  Its last bit must not decide whether the chamfer's triangle holds a
    singular point: it never does, nudged either way, in the mirror image too."""
    from quadcnn_wb.core.field.framefield import (
        boundary_edges,
        boundary_values,
        solve_cross_field,
        triangle_windings,
    )

    mesh = _chamfered_square_fan()
    z = solve_cross_field(mesh, boundary_values(mesh))
    assert abs(z[2] + z[3]) < 1e-12  # the tie this test is about
    edges = boundary_edges(mesh)
    assert (2, 3) in edges and len(edges) == 5
    for nudge in (-1e-12, 0.0, 1e-12):
        nudged = z.copy()
        nudged[3] *= np.exp(1j * nudge)
        assert not triangle_windings(nudged, mesh.triangles, edges).any()
        # mirrored: the conjugate field, each triangle walked the other way round
        assert not triangle_windings(np.conj(nudged), mesh.triangles[:, ::-1], edges).any()
    # without the boundary edges, round-off decides: the test's tie is a real one
    plain = {int(triangle_windings(z * np.exp(1j * np.array([0, 0, 0, n, 0, 0])),
                                   mesh.triangles).sum()) for n in (-1e-12, 1e-12)}
    assert plain == {0, 1}


def test_a_field_real_along_a_curve_has_no_zeros_on_it():
    """z real on a strip of triangles, changing sign across it: the linear z is zero along
    a line, no point; wrapped alone each triangle across it read as a zero, all one way."""
    from quadcnn_wb.core.field.framefield import triangle_windings

    xs, ys = np.arange(-2.5, 3.0, 1.0), np.arange(0.0, 4.0, 1.0)
    nodes = np.array([(x, y) for y in ys for x in xs])
    nx = len(xs)
    triangles = []
    for j in range(len(ys) - 1):
        for i in range(nx - 1):
            a, b, c, d = j * nx + i, j * nx + i + 1, (j + 1) * nx + i + 1, (j + 1) * nx + i
            triangles += [(a, b, c), (a, c, d)]
    triangles = np.array(triangles)
    z = nodes[:, 0] + 0j  # -2.5 ... 2.5: the sign changes between x = -0.5 and 0.5
    assert not triangle_windings(z, triangles).any()
    assert not triangle_windings(-z, triangles).any()
    # a real zero next to it still counts
    assert triangle_windings((nodes[:, 0] - 0.2) + 1j * (nodes[:, 1] - 1.3),
                             triangles).sum() == 1


def test_a_bow_tie_of_right_triangles_is_blocks_around_two_points():
    """Two right triangles meeting at their right angles across a 0.1 neck, legs at 45° to
    the bases (held-out SO-ARM101 Seeed mounting plate f23): z is real everywhere, and
    the curve where it changes sign gave 262 valence-5 points and two minutes of
    segment-count programs before gmsh's quads stood in."""
    from quadcnn_wb.core.input.domain import domain_from_json
    from quadcnn_wb.core.pipeline import mesh_domain

    ring = [(-0.05, 0.0), (-9.1, -9.05), (9.1, -9.05), (0.05, 0.0), (9.1, 9.05), (-9.1, 9.05)]
    loop = [{"line": [list(p), list(q)]} for p, q in zip(ring, ring[1:] + ring[:1])]
    result = mesh_domain(domain_from_json({"loops": [loop]}))
    assert result.structured_share == 1.0, result.problem
    assert len(result.reference.field.singularities) <= 2
    assert result.quality["blocks"] <= 12
    assert result.quality["min_scaled_jacobian"] > 0.6
