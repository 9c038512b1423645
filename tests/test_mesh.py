"""The numerical path end to end: valid conforming meshes, regular but for the singular
points, quantization equalities, exports that read back."""

from __future__ import annotations

import functools
import json
import re

import meshio
import numpy as np
import pytest
from conftest import EXAMPLE_NAMES, SHARED_EXAMPLES, run_cli
from shapes import OWN_SHAPES, named_domain

from quadcnn_wb.bench.meshcheck import check_quad_mesh
from quadcnn_wb.core.input.load import load_domain
from quadcnn_wb.core.layout.quantize import side_counts
from quadcnn_wb.core.pipeline import mesh_domain

# The crescent's 15° tips bound its worst quad, and its kites' inner corners are
# irregular beside no singular point: test_cusps checks it for what a cusp allows.
MESHABLE_OWN = [name for name in OWN_SHAPES if name != "crescent"]


@functools.cache
def meshed(name):
    return mesh_domain(named_domain(name))


def on_boundary_of(domain):
    tol = 1e-9 * domain.size

    def test(p):
        return any(np.hypot(*(c.point(c.project(p)) - p)) <= tol
                   for loop in domain.loops for c in loop)
    return test


@pytest.mark.parametrize("name", EXAMPLE_NAMES + MESHABLE_OWN)
def test_mesh_is_valid_and_conforming(name):
    result = meshed(name)
    mesh, domain = result.mesh, result.domain
    boundary_edges = check_quad_mesh(mesh.nodes, mesh.quads, domain.area, on_boundary_of(domain))
    on_curve = on_boundary_of(domain)
    assert all(on_curve(mesh.nodes[i]) for i in np.nonzero(mesh.boundary)[0])
    assert {n for e in boundary_edges for n in e} == set(np.nonzero(mesh.boundary)[0])
    assert len(mesh.block_of_quad) == len(mesh.quads)
    assert result.quality["min_scaled_jacobian"] > 0.5


@pytest.mark.parametrize("name", EXAMPLE_NAMES + MESHABLE_OWN)
def test_only_the_singular_points_are_irregular(name):
    result = meshed(name)
    # ... and the corners a small concave fillet is read as (input.features): three quads
    # where the boundary is smooth, irregular by DESIGN.md's definition (the thin wall).
    # (A small round hole's square has four such corners.)
    fillets = result.feature_corners
    assert result.quality["irregular_vertices"] == \
        len(result.reference.field.singularities) + fillets
    mesh = result.mesh
    count = np.bincount(mesh.quads.ravel(), minlength=len(mesh.nodes))
    for s in result.reference.field.singularities:
        # Partition vertices are the mesh's first nodes; smoothing may have moved them.
        node = int(np.argmin(np.hypot(*(result.partition.vertices - s.xy).T)))
        assert count[node] == s.valence


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_opposite_block_sides_have_equal_segment_counts(name):
    result = meshed(name)
    assert (result.counts >= 1).all()
    for sides in side_counts(result.partition, result.counts):
        assert sides[0] == sides[2] and sides[1] == sides[3]
    assert len(result.partition.blocks) == result.quality["blocks"]


def test_element_size_follows_the_request():
    domain = load_domain(SHARED_EXAMPLES / "l_shape.json")
    coarse, fine = mesh_domain(domain, size=0.2), mesh_domain(domain, size=0.05)
    assert coarse.quality["quads"] == 75  # 3 unit squares at 5x5 each
    assert fine.quality["quads"] == 1200


def test_annulus_gets_a_cut_and_meshes():
    result = meshed("annulus")
    assert len(result.cuts) == 1 and result.quality["blocks"] == 1
    assert result.quality["irregular_vertices"] == 0


def test_a_plate_with_bolt_holes_all_over_gets_blocks_at_both_sizes():
    """Nine 3 mm holes in a grid on a 200 mm plate: the background could not be had
    (gmsh spread the holes' sizes over the plate) and the part was refused."""
    from conftest import circle, rect

    from quadcnn_wb.core.input.domain import domain_from_json
    from quadcnn_wb.core.input.pose import diameter
    from quadcnn_wb.core.pipeline import mesh_domain

    domain = domain_from_json({"loops": [rect(200, 200)] + [
        circle(20 + 80 * i, 20 + 80 * j, 1.5) for i in range(3) for j in range(3)]})
    for size in (None, diameter(domain) / 100):
        result = mesh_domain(domain, size=size)
        assert result.structured_share == 1.0
        mesh = result.mesh
        check_quad_mesh(mesh.nodes, mesh.quads, result.domain.area,
                        on_boundary_of(result.domain))
        assert result.quality["min_scaled_jacobian"] > 0.9


def test_mesh_exports_read_back(tmp_path):
    result = meshed("plate_hole")
    from quadcnn_wb.core.mesh.export import export

    for suffix in (".msh", ".vtk"):
        export(result, tmp_path / f"m{suffix}")
        back = meshio.read(tmp_path / f"m{suffix}")
        assert back.cells[0].type == "quad"
        assert np.array_equal(back.cells[0].data, result.mesh.quads)
        assert np.allclose(back.points[:, :2], result.mesh.nodes)
    export(result, tmp_path / "m.inp")
    text = (tmp_path / "m.inp").read_text()
    assert "*ELEMENT, TYPE=CPS4, ELSET=EALL" in text
    for name in ("LOOP0", "LOOP1", "LOOP0_SEG2", "BLOCK0"):
        assert f"={name}\n" in text
    back = meshio.read(tmp_path / "m.inp", file_format="abaqus")
    assert len(back.points) == len(result.mesh.nodes)
    assert sum(len(c.data) for c in back.cells) == len(result.mesh.quads)


def test_mesh_command_json_contract(tmp_path):
    out, png = tmp_path / "mesh.json", tmp_path / "mesh.png"
    result = run_cli("mesh", SHARED_EXAMPLES / "plate_hole.json", "--method", "numerical",
                     "--size", "0.08", "-o", out, "--png", png)
    assert result.returncode == 0, result.stderr
    data = json.loads(out.read_text())
    assert set(data) >= {"nodes", "quads", "block_of_quad", "singularities", "streamlines",
                         "method", "fallback", "quality", "timings"}
    assert data["method"] == "numerical" and data["fallback"] == []
    assert set(data["quality"]) == {"min_scaled_jacobian", "mean_scaled_jacobian",
                                    "irregular_vertices", "blocks", "quads"}
    assert data["quality"]["irregular_vertices"] == 4
    assert "total" in data["timings"]
    assert len(data["block_of_quad"]) == len(data["quads"]) == data["quality"]["quads"]
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_mesh_command_refuses_what_it_cannot_do(tmp_path):
    for args, message in ((["--method", "cnn"], "no model for this domain's topology"),
                          (["--size", "-1"], "expected a positive size"),
                          (["-o", str(tmp_path / "m.stl")], "output must end in")):
        result = run_cli("mesh", SHARED_EXAMPLES / "l_shape.json", *args)
        assert result.returncode == 2, result.stderr
        assert result.stderr.startswith("error:") and message in result.stderr


def test_faces_that_are_not_blocks_get_conforming_unstructured_quads():
    from quadcnn_wb.core.layout.cuts import connecting_cuts
    from quadcnn_wb.core.layout.partition import build_partition
    from quadcnn_wb.core.mesh.orientation import tiles_exactly
    from quadcnn_wb.core.mesh.validity import free_edges_on_boundary
    from quadcnn_wb.core.rounds import MIN_VALID_JACOBIAN, _rounds

    result = meshed("plate_hole")
    lines = list(result.reference.streamlines)
    incomplete = [line for line in lines if line.end.kind != "singularity"][1:]
    ref = result.reference
    partition = build_partition(result.domain, incomplete, ref.mesh.element_size)
    assert partition.free_faces
    assert all(re.search("corners instead of 4|turns back|too concave", face.reason)
               for face in partition.free_faces)
    # The rounds without the last resort (which since a block's quads are turned together
    # makes these faces blocks round a centre): the free faces' own quads are tested here.
    cuts = connecting_cuts(result.domain, ref.mesh, ref.field, incomplete)
    timings = {"partition": 0.0, "quantization": 0.0, "quad_mesh": 0.0}
    state = {"dissolve": frozenset(), "freed": set(), "unbalanced": set(), "cuts": cuts,
             "fold_cuts": None}
    _, partition, counts, mesh = _rounds(result.domain, ref.mesh, incomplete,
                                         result.size, True, timings, True,
                                         MIN_VALID_JACOBIAN, False, False, state)
    free = mesh.block_of_quad < 0
    assert free.any() and not free.all()  # only the free faces lost their blocks
    assert tiles_exactly(mesh.nodes, mesh.quads)
    assert free_edges_on_boundary(mesh.quads, mesh.boundary)
    check_quad_mesh(mesh.nodes, mesh.quads, result.domain.area, on_boundary_of(result.domain))
    edges = [e for face in partition.free_faces for e, _ in face.halves]
    assert all(counts[e] >= 2 and counts[e] % 2 == 0 for e in edges)


def test_the_hexagons_near_coincident_singular_points_get_blocks():
    # A regular hexagon's field splits a valence-6 point into two valence-5 points a hair
    # apart; the separatrices between them run side by side and collapse into one mesh line
    # (zero segment counts), where a partition without the T-mesh found no blocks at all.
    result = meshed("hexagon")
    assert result.structured and result.structured_share == 1.0, result.problem
    assert result.quality["irregular_vertices"] == len(result.reference.field.singularities)
    check_quad_mesh(result.mesh.nodes, result.mesh.quads, result.domain.area,
                    on_boundary_of(result.domain))
    assert result.to_json()["structured"] is True


def test_three_cornered_faces_are_split_into_blocks():
    # A 22° corner rounds to zero quarter turns: the face there has three corners, which
    # midpoint subdivision turns into three blocks around one extra valence-3 vertex.
    from shapes import polygon

    from quadcnn_wb.core.input.domain import domain_from_json

    domain = domain_from_json({"loops": [polygon([[0, 0], [3, 0], [0, 1.2]])]})
    result = mesh_domain(domain)
    assert result.structured and result.quality["blocks"] == 3
    check_quad_mesh(result.mesh.nodes, result.mesh.quads, domain.area, on_boundary_of(domain))
    assert result.quality["irregular_vertices"] == 1
    assert result.quality["min_scaled_jacobian"] > 0.3


def test_overlapping_blocks_are_detected():
    from quadcnn_wb.core.mesh.orientation import tiles_exactly

    nodes = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [2, 0], [2, 1]], dtype=float)
    side_by_side = np.array([[0, 1, 2, 3], [1, 4, 5, 2]])
    stacked = np.array([[0, 1, 2, 3], [1, 4, 5, 2], [0, 1, 2, 3]])  # one quad twice
    assert tiles_exactly(nodes, side_by_side)
    assert not tiles_exactly(nodes, stacked)  # every corner is fine, the cover is not


def test_two_traces_ending_a_rounding_error_apart_on_a_rim_share_one_vertex():
    # They once left a boundary edge of no length between two vertices in one place, and
    # the hole's ring of a face came out as one point (bracket_plate, nist_ctc04_plate).
    from quadcnn_wb.core.input.domain import domain_from_json
    from quadcnn_wb.core.layout.partition import build_partition
    from quadcnn_wb.core.layout.streamlines import Endpoint, Streamline

    domain = domain_from_json({"loops": [
        [{"line": [[0, 0], [2, 0]]}, {"line": [[2, 0], [2, 1]]}, {"line": [[2, 1], [0, 1]]},
         {"line": [[0, 1], [0, 0]]}],
        [{"circle": {"center": [1, 0.5], "radius": 0.25}}]]})
    rim = domain.loops[1][0]
    h = 0.05
    lines = []
    for start, start_seg, tip in (((0.0, 0.5), 3, (0.75, 0.5)),
                                  ((0.75, 1.0), 2, (0.75, 0.5 + 1e-10))):
        t_rim = float(rim.project(np.array(tip)))
        t_outer = float(domain.loops[0][start_seg].project(np.array(start)))
        points = np.linspace(start, rim.point(t_rim), 20)
        lines.append(Streamline(points, Endpoint("boundary", loop=0, segment=start_seg,
                                                 param=t_outer),
                                Endpoint("boundary", loop=1, segment=0, param=t_rim)))
    partition = build_partition(domain, lines, h)
    rim_vertices = {v for edge in partition.edges if edge.is_boundary
                    and edge.pieces[0].loop == 1 for v in (edge.a, edge.b)}
    assert len(rim_vertices) == 1
    assert min(edge.length for edge in partition.edges) > 1e-6 * h


@pytest.mark.parametrize("shift", [0, 1])
def test_a_free_face_keeps_a_notch_tip_among_gmsh_nodes(shift):
    # gmsh meshes every other side node; a notch's tip left between two of them was cut
    # off by its chord, and the quads pulled out to the tip folded (nist_ctc01_plate).
    from quadcnn_wb.core.input.domain import domain_from_json
    from quadcnn_wb.core.input.pose import canonical_pose
    from quadcnn_wb.core.mesh.free_faces import free_face_quads
    from quadcnn_wb.core.mesh.orientation import signed_areas
    from quadcnn_wb.core.mesh.quadmesh import scaled_jacobians

    steps = np.arange(0, 4, 0.5)
    ring = np.array([(x, 0.0) for x in steps] + [(4.0, y) for y in steps[:4]]
                    + [(4 - x, 2.0 if x != 2 else 0.9) for x in steps]
                    + [(0.0, 2 - y) for y in steps[:4]])
    ring = np.roll(ring, -shift, axis=0)  # the tip at an even, then an odd place
    domain = domain_from_json({"loops": [[
        {"line": [[0, 0], [4, 0]]}, {"line": [[4, 0], [4, 2]]}, {"line": [[4, 2], [0, 2]]},
        {"line": [[0, 2], [0, 0]]}]]})
    interior, quads = free_face_quads([ring], canonical_pose(domain))
    points = np.vstack([ring, interior])
    if signed_areas(points, quads).sum() < 0:
        quads = quads[:, ::-1]
    assert scaled_jacobians(points, quads).min() > 0.2


def test_segment_counts_without_a_proven_optimum_are_refused_not_taken():
    # A time-limited answer of the integer program would make the counts (and the mesh)
    # depend on the machine's speed: past its time limit quantize refuses instead.
    from quadcnn_wb.core.layout.partition_types import PartitionError
    from quadcnn_wb.core.layout.quantize import InfeasibleCounts, quantize

    result = meshed("four_hole")
    counts = quantize(result.partition, result.size)
    assert np.array_equal(counts, result.counts)  # the same program, proven in time
    with pytest.raises(PartitionError) as refused:
        quantize(result.partition, result.size, time_limit=1e-9)
    assert not isinstance(refused.value, InfeasibleCounts)  # not mistaken for "no counts"
    assert "no proven optimum" in str(refused.value)


def _side_slide(t):
    from quadcnn_wb.core.input.curves import Line
    from quadcnn_wb.core.mesh.improve import BoundarySlide

    side = Line(np.array([0.0, 0.0]), np.array([2.0, 0.0]))
    return {1: BoundarySlide(curve=side, t=t, before=None, after=None, t_before=0.0,
                             t_after=1.0)}


def test_a_boundary_node_slides_along_its_curve_until_its_quads_are_fair():
    """A side node left at 0.9 of a straight side skews the quads above it; the max-min
    move slides it along the side (never off it) until they are fair (SLIDE_BELOW), and
    no further: elsewhere the boundary keeps its even spacing.  (Two layers of quads: the
    middle node is free.)"""
    from quadcnn_wb.core.mesh.improve import SLIDE_BELOW, improve_worst, sj_batch

    nodes = np.array([[0, 0], [1.8, 0], [2, 0], [0, 0.3], [1, 0.3], [2, 0.3],
                      [0, 0.6], [1, 0.6], [2, 0.6]], dtype=float)
    quads = np.array([[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]])
    fixed = np.ones(len(nodes), dtype=bool)
    fixed[4] = False
    slides = _side_slide(0.9)
    moved = improve_worst(nodes, quads, fixed, passes=40, slides=slides)
    assert moved[1, 1] == 0.0 and 1.0 < moved[1, 0] < 1.8
    assert slides[1].t == pytest.approx(moved[1, 0] / 2.0)
    assert sj_batch(moved[quads]).min() >= SLIDE_BELOW > sj_batch(nodes[quads]).min()
    assert moved[[0, 2, 3, 5, 6, 7, 8]] == pytest.approx(nodes[[0, 2, 3, 5, 6, 7, 8]])
    fair = nodes.copy()
    fair[1, 0] = 1.2  # its quads above SLIDE_BELOW already: the node stays
    assert sj_batch(fair[quads[:2]]).min() >= SLIDE_BELOW
    out = improve_worst(fair, quads, fixed, slides=_side_slide(0.6))
    assert out[1] == pytest.approx(fair[1])


def test_in_a_strip_one_element_thick_a_boundary_node_slides_until_the_quads_are_square():
    """With no free node (a strip one element thick: held-out 0086, a thin strip bent
    round a fillet, 0.70 where gmsh has 0.996) nothing but sliding mends the shear, and
    it goes on past SLIDE_BELOW."""
    from quadcnn_wb.core.mesh.improve import SLIDE_BELOW, improve_worst, sj_batch, strip_slides

    nodes = np.array([[0, 0], [1.8, 0], [2, 0], [0, 0.3], [1, 0.3], [2, 0.3]], dtype=float)
    quads = np.array([[0, 1, 4, 3], [1, 2, 5, 4]])
    fixed = np.ones(len(nodes), dtype=bool)
    assert improve_worst(nodes, quads, fixed) == pytest.approx(nodes)  # fixed: stays
    slides = _side_slide(0.9)
    moved = strip_slides(nodes, quads, fixed, slides)
    assert moved[1, 1] == 0.0 and slides[1].t == pytest.approx(moved[1, 0] / 2.0)
    assert sj_batch(moved[quads]).min() > 0.99 > SLIDE_BELOW
    assert moved[[0, 2, 3, 4, 5]] == pytest.approx(nodes[[0, 2, 3, 4, 5]])


def test_the_worst_corners_round_a_singular_point_are_raised_together():
    """Three quads round a valence-3 point (a regular hexagon's halves): the best the
    point can do is 120 degrees at every corner it touches, sin 120 = 0.8660 everywhere.
    Moved off its place, one-node compass steps bring it back only to within their step;
    the polish moves the free nodes as one (held-out 0090, a disc, 0.8631 -> 0.8660 where
    gmsh has 0.8655) and leaves the fixed ones where they are."""
    from quadcnn_wb.core.mesh.improve import polish_worst, sj_batch

    ring = [[np.cos(a), np.sin(a)] for a in np.radians(np.arange(0, 360, 60))]
    nodes = np.array([[0.23, -0.11]] + ring)
    quads = np.array([[0, 1, 2, 3], [0, 3, 4, 5], [0, 5, 6, 1]])
    fixed = np.ones(len(nodes), dtype=bool)
    fixed[0] = False
    assert sj_batch(nodes[quads]).min() < 0.8
    polished = polish_worst(nodes, quads, fixed)
    assert sj_batch(polished[quads]).min() == pytest.approx(np.sin(np.radians(120)), abs=1e-6)
    assert polished[0] == pytest.approx([0.0, 0.0], abs=1e-4)
    assert polished[1:] == pytest.approx(nodes[1:])
    fixed[0] = True  # nothing free: nothing moves
    assert polish_worst(nodes, quads, fixed) == pytest.approx(nodes)


@pytest.mark.parametrize(("name", "corners_round_a_point"), [
    ("disk", 3), ("stadium", 3), ("plate, 1 hole", 5), ("pentagon", 5)])
def test_a_mesh_bounded_by_its_singular_points_reaches_their_best_corner(name,
                                                                       corners_round_a_point):
    """Where nothing but the singular points bounds the quality (no sharp corner), the
    worst quad is the one the points allow: 360/k degrees at a point of valence k, so
    sin 120 = 0.8660 for valence 3 and sin 72 = 0.9511 for valence 5 (before the
    polish: 0.8631, 0.8637, 0.9488 and 0.9511)."""
    best = abs(np.sin(np.radians(360 / corners_round_a_point)))
    assert meshed(name).quality["min_scaled_jacobian"] == pytest.approx(best, abs=1e-6)


def test_of_two_layouts_a_near_flat_quad_outweighs_a_higher_structured_share():
    """mesh_domain keeps the better of two backgrounds' meshes: more of it in blocks,
    then the better worst element, but one with a quad under FAIR_JACOBIAN loses."""
    from quadcnn_wb.core.mesh.quadmesh import QuadMesh
    from quadcnn_wb.core.rounds import FAIR_JACOBIAN, mesh_key

    def strip(top_shift, blocks):
        # Two quads side by side; shifting the top middle node skews both.
        nodes = np.array([[0, 0], [1, 0], [2, 0], [0, 1], [1 + top_shift, 1], [2, 1]], float)
        quads = np.array([[0, 1, 4, 3], [1, 2, 5, 4]])
        return QuadMesh(nodes=nodes, quads=quads, block_of_quad=np.array(blocks),
                        boundary=np.ones(6, bool), edge_nodes=())

    all_blocks_fine = strip(0.3, [0, 1])
    all_blocks_sliver = strip(4.0, [0, 1])
    half_blocks_fair = strip(0.5, [0, -1])
    assert mesh_key(all_blocks_sliver)[2] < FAIR_JACOBIAN < mesh_key(half_blocks_fair)[2]
    assert mesh_key(half_blocks_fair) > mesh_key(all_blocks_sliver)
    assert mesh_key(all_blocks_fine) > mesh_key(half_blocks_fair)


def test_boundary_nodes_slide_across_smooth_joints_but_not_past_corners():
    """A boundary edge's stretches (quadmesh._EdgeChain) run over the joints that turn
    under SMOOTH_TURN (a polyline's, a tangent arc's), so its nodes can slide from one
    curve to the next there; a real corner inside the edge (a step's) bounds them."""
    import math

    from shapes import polygon

    from quadcnn_wb.core.input.domain import domain_from_json
    from quadcnn_wb.core.layout.partition_types import BoundaryPiece, Edge
    from quadcnn_wb.core.mesh.quadmesh import _EdgeChain

    # A plate with a half-disc notch in its top edge, the notch a 30-line polyline.
    arc = [[2 + math.cos(a), 2 - math.sin(a)] for a in np.linspace(0, math.pi, 31)]
    domain = domain_from_json({"loops": [polygon([[0, 0], [4, 0], [4, 2]] + arc + [[0, 2]])]})
    loop = domain.loops[0]
    assert len(loop) == 35
    # An edge along the top: [4,2]->[3,2], the notch, [1,2]->[0,2]; a corner at each end
    # of the notch, 30 smooth joints inside it.
    pieces = tuple(BoundaryPiece(0, si, 0.0, 1.0) for si in range(2, 34))
    chain = _EdgeChain(domain, Edge(points=np.zeros((2, 2)), a=0, b=1, pieces=pieces))
    assert chain.stretch_of == [0] + [1] * 30 + [2]
    lo, hi = chain.stretch_bounds(1)
    assert hi - lo == pytest.approx(sum(c.length for c in loop[3:33]))
    middle = chain.point(0.5 * (lo + hi))
    assert np.hypot(*(middle - [2, 2])) == pytest.approx(1.0, abs=0.01)  # on the arc


def test_corner_jacobians_match_the_design_formula_bit_for_bit():
    """The fast form (one edge array, the previous edge reversed) must give exactly
    DESIGN.md's (a x b) / (|a||b|) with a to the next corner and b to the previous: the
    max-min moves compare these values for ties, so a last-bit change would move nodes."""
    from quadcnn_wb.core.mesh.improve import corner_jacobians

    rng = np.random.default_rng(3)
    p = rng.normal(size=(500, 4, 2)) * np.exp(rng.normal(size=(500, 4, 2)) * 4)
    p[0] = p[0, 0]  # all corners on one point
    p[1, 1] = p[1, 0]  # one zero-length edge
    fast = corner_jacobians(p)
    for q in range(len(p)):
        for k in range(4):
            a = p[q, (k + 1) % 4] - p[q, k]
            b = p[q, (k - 1) % 4] - p[q, k]
            norm = np.hypot(*a) * np.hypot(*b)
            expected = (a[0] * b[1] - a[1] * b[0]) / norm if norm > 0 else -1.0
            assert fast[q, k] == expected


def test_neighbour_means_are_the_plain_average_bit_for_bit():
    """Smoothing's average of each node's edge neighbours, summed in the order of the
    edge list (first ends, then second ends), as a loop would."""
    from quadcnn_wb.core.mesh.edge_graph import edge_graph, neighbour_means

    rng = np.random.default_rng(4)
    quads = rng.integers(0, 300, size=(400, 4))
    x = rng.normal(size=(310, 2)) * 1e3
    edges, degree = edge_graph(quads, len(x))
    means = neighbour_means(x, edges, degree)
    summed = np.zeros_like(x)
    for i, j in edges:
        summed[i] += x[j]
    for i, j in edges:
        summed[j] += x[i]
    used = degree > 0
    assert np.array_equal(means[used], summed[used] / degree[used, None])
    assert np.isnan(means[~used]).all()


def test_longest_edge_is_the_longest_side_of_any_quad():
    from quadcnn_wb.core.mesh.quadmesh import QuadMesh
    from quadcnn_wb.core.mesh.quality import longest_edge

    # Two quads side by side: 1 x 1 and 3 x 1 (the long one's bottom and top are 3).
    nodes = np.array([[0, 0], [1, 0], [4, 0], [4, 1], [1, 1], [0, 1]], dtype=float)
    quads = np.array([[0, 1, 4, 5], [1, 2, 3, 4]])
    mesh = QuadMesh(nodes=nodes, quads=quads, block_of_quad=np.zeros(2, dtype=int),
                    boundary=np.ones(6, dtype=bool), edge_nodes=())
    assert longest_edge(mesh) == pytest.approx(3.0)
