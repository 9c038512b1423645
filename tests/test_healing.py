"""What CAD kernels deliver is healed and reported; real gaps and crossings stay errors."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from conftest import rect, run_cli

from quadcnn_wb.core.input.curves import Line
from quadcnn_wb.core.input.domain import DomainError, domain_from_json, make_domain
from quadcnn_wb.core.input.healing import (
    HEAL_TOL,
    VERTEX_SNAP,
    onto_shared_vertices,
    vertex_note,
)
from quadcnn_wb.core.pipeline import mesh_domain

L = lambda a, b: {"line": [a, b]}  # noqa: E731


def arcs(center, radius, angles):
    """A loop of arcs of one circle through the given angles (radians)."""
    def at(t):
        return [center[0] + radius * math.cos(t), center[1] + radius * math.sin(t)]

    return [{"arc": [at(a), at(0.5 * (a + b)), at(b)]} for a, b in zip(angles[:-1], angles[1:])]


SPLITS = {"2x180": [0, 180, 360], "3x120": [0, 120, 240, 360], "4x90": [0, 90, 180, 270, 360],
          "90+270": [0, 90, 360]}


@pytest.mark.parametrize("split", SPLITS)
@pytest.mark.parametrize("offset", [0.0, 17.0, 133.0])
def test_a_hole_stored_as_arcs_is_one_circle(split, offset):
    angles = [math.radians(a + offset) for a in SPLITS[split]]
    domain = domain_from_json({"loops": [rect(100, 60), arcs([50, 30], 10, angles)]})
    (hole,) = domain.loops[1]
    assert hole.kind == "circle" and hole.radius == pytest.approx(10)
    assert domain.area == pytest.approx(6000 - math.pi * 100)
    assert any("arcs of one circle merged" in note for note in domain.healed)


def test_a_hole_of_arcs_meshes_like_the_circle():
    whole = domain_from_json({"loops": [rect(100, 60), [{"circle": {"center": [50, 30],
                                                                     "radius": 10}}]]})
    split = domain_from_json({"loops": [rect(100, 60),
                                        arcs([50, 30], 10, [math.radians(a) for a in
                                                            (0, 90, 180, 270, 360)])]})
    a, b = mesh_domain(whole), mesh_domain(split)
    assert a.structured and b.structured
    assert a.quality["quads"] == b.quality["quads"]
    assert a.quality["irregular_vertices"] == b.quality["irregular_vertices"]


def test_a_fillet_run_of_two_arcs_is_one_arc():
    # A quarter round corner stored as two 45° arcs.
    c, r = [80, 40], 20
    quarter = arcs(c, r, [0, math.pi / 4, math.pi / 2])
    loop = [L([0, 0], [100, 0]), L([100, 0], [100, 40]), *quarter, L([80, 60], [0, 60]),
            L([0, 60], [0, 0])]
    domain = domain_from_json({"loops": [loop]})
    assert [c.kind for c in domain.loops[0]] == ["line", "line", "arc", "line", "line"]
    assert domain.healed


def test_collinear_lines_merge_and_the_part_is_unchanged():
    loop = [L([0, 0], [40, 0]), L([40, 0], [100, 0]), L([100, 0], [100, 60]),
            L([100, 60], [0, 60]), L([0, 60], [0, 0])]
    domain = domain_from_json({"loops": [loop]})
    assert len(domain.loops[0]) == 4 and domain.area == pytest.approx(6000)
    assert any("collinear lines merged" in note for note in domain.healed)


def test_clean_input_reports_no_healing():
    assert domain_from_json({"loops": [rect(100, 60)]}).healed == ()


def test_micrometre_gaps_of_a_300_mm_part_are_joined():
    gap = 5e-3  # 5 µm in mm
    loop = [L([0, 0], [300, 0]), L([300, gap], [300, 200]), L([300 + gap, 200], [0, 200]),
            L([0, 200 - gap], [0, 0])]
    domain = domain_from_json({"loops": [loop, arcs([150, 100], 30, [0, math.pi, 2 * math.pi])]})
    notes = " ".join(domain.healed)
    assert "joined 3 gap(s)" in notes and "arcs of one circle" in notes
    assert domain.area == pytest.approx(300 * 200 - math.pi * 900, rel=1e-6)


def test_a_real_gap_stays_an_error():
    size = math.hypot(300, 200)
    gap = 20 * HEAL_TOL * size
    loop = [L([0, 0], [300, 0]), L([300, gap], [300, 200]), L([300, 200], [0, 200]),
            L([0, 200], [0, 0])]
    with pytest.raises(DomainError, match=r"loop 0: open loop, segment 0 ends at .*\(gap"):
        domain_from_json({"loops": [loop]})


def test_a_hole_of_arcs_that_do_not_close_is_an_open_loop():
    hole = arcs([50, 30], 10, [0, math.pi, 1.9 * math.pi])
    with pytest.raises(DomainError, match=r"loop 1: open loop"):
        domain_from_json({"loops": [rect(100, 60), hole]})


def test_arcs_of_one_circle_that_double_back_still_overlap():
    hole = arcs([50, 30], 10, [0, math.pi, 2 * math.pi]) + arcs([50, 30], 10, [0, math.pi])[::-1]
    with pytest.raises(DomainError, match=r"loop 1"):
        domain_from_json({"loops": [rect(100, 60), hole]})


def test_a_crumb_edge_is_dropped():
    loop = [L([0, 0], [100, 0]), L([100, 0], [100, 1e-6]), L([100, 1e-6], [100, 60]),
            L([100, 60], [0, 60]), L([0, 60], [0, 0])]
    domain = domain_from_json({"loops": [loop]})
    assert len(domain.loops[0]) == 4
    assert any("dropped 1 segment" in note for note in domain.healed)


def test_arcs_of_one_circle_apart_in_a_loop_are_no_overlap():
    # A round boss with a flat cut (a D shape): both arcs lie on one circle but are not
    # consecutive, and they only touch the flat's ends.
    r = 10
    a = math.radians(30)
    p, q = [r * math.cos(a), r * math.sin(a)], [r * math.cos(a), -r * math.sin(a)]
    up = arcs([0, 0], r, [a, math.pi])[0]
    down = arcs([0, 0], r, [math.pi, 2 * math.pi - a])[0]
    domain = domain_from_json({"loops": [[L(q, p), up, down]]})
    assert [c.kind for c in domain.loops[0]] == ["line", "arc"]  # the two arcs merge


def test_healing_is_reported_on_the_command_line(write_json, tmp_path):
    path = write_json({"loops": [rect(100, 60), arcs([50, 30], 10, [0, math.pi,
                                                                       2 * math.pi])]})
    out = tmp_path / "mesh.json"
    run = run_cli("mesh", path, "-o", out)
    assert run.returncode == 0, run.stderr
    assert "healed: loop 1: 1 joint(s) between arcs of one circle merged" in run.stdout
    data = json.loads(out.read_text())
    assert data["healed"] == ["loop 1: 1 joint(s) between arcs of one circle merged"]
    assert data["structured_share"] == 1.0


def _notched_plate_with_split_edges(start: int, reverse: bool) -> dict:
    """A plate whose bottom edge is stored as three collinear lines and whose top carries a
    small round notch stored as 40 short lines, each joint of which is collinear within
    the healing tolerance; the loop starts at piece ``start`` and may run backwards."""
    notch = [[50 + 2 * math.cos(a), 60 - 2 * math.sin(a)]
             for a in (math.pi * k / 40 for k in range(41))]
    points = [[0, 0], [30, 0], [70, 0], [100, 0], [100, 60], *notch, [0, 60]]
    loop = [L(p, q) for p, q in zip(points, points[1:] + points[:1])]
    if reverse:
        loop = [L(s["line"][1], s["line"][0]) for s in reversed(loop)]
    return {"loops": [loop[start:] + loop[:start]]}


def _vertices(domain) -> set:
    return {tuple(round(float(x), 9) for x in c.p0) for c in domain.loops[0]}


@pytest.mark.parametrize("start,reverse", [(0, False), (2, False), (20, False), (7, True)])
def test_a_run_of_lines_keeps_its_shape_from_any_start(start, reverse):
    # Judged joint by joint, each of the notch's joints bows out by less than the healing
    # tolerance; merged one after another they became chords across the notch, and which
    # ones depended on where the loop started.  Now the split edge becomes one line, the
    # notch keeps every given vertex within the tolerance, and the start does not matter.
    given = _notched_plate_with_split_edges(start, reverse)
    domain = domain_from_json(given)
    vertices = _vertices(domain)
    assert (30.0, 0.0) not in vertices and (70.0, 0.0) not in vertices
    assert 4 + 3 < len(vertices) < 4 + 41  # the notch simplified, not flattened
    tol = HEAL_TOL * domain.size
    for segment in given["loops"][0]:
        x, y = segment["line"][0]
        assert min(_distance_to(c, x, y) for c in domain.loops[0]) <= tol
    assert vertices == _vertices(domain_from_json(_notched_plate_with_split_edges(0, False)))


def _distance_to(line, x, y) -> float:
    d = line.p1 - line.p0
    t = min(1.0, max(0.0, ((x - line.p0[0]) * d[0] + (y - line.p0[1]) * d[1]) / (d @ d)))
    return math.hypot(x - line.p0[0] - t * d[0], y - line.p0[1] - t * d[1])


def test_healing_a_healed_loop_changes_nothing():
    healed = domain_from_json(_notched_plate_with_split_edges(5, False))
    again = domain_from_json(healed.to_json())
    assert again.healed == ()
    assert _vertices(again) == _vertices(healed)


def test_an_arc_whose_end_was_joined_reads_back_from_its_json_as_the_same_arc():
    # A plate round a 340° arc whose start the last line misses by 2e-5 of the part: the
    # join moves the arc's start off its circle.  Its JSON (ends and middle)
    # must read back as the arc the domain holds, so a part saved and loaded again gets
    # the same mesh.
    c, r = [0.0, 0.0], 30.0
    gap = 2e-5 * 100
    start, end = math.radians(-170), math.radians(170)
    at = lambda t: [c[0] + r * math.cos(t), c[1] + r * math.sin(t)]  # noqa: E731
    tip, foot = at(end), at(start)
    loop = [{"arc": [foot, at(0.0), tip]}, L(tip, [-70.0, tip[1]]),
            L([-70.0, tip[1]], [-70.0, foot[1]]), L([-70.0, foot[1]], [foot[0], foot[1] - gap])]
    domain = domain_from_json({"loops": [loop]})
    assert any("joined" in note for note in domain.healed)
    again = domain_from_json(json.loads(json.dumps(domain.to_json())))
    for given, read in zip(domain.loops[0], again.loops[0]):
        assert given.kind == read.kind
        if given.kind == "arc":
            assert math.dist(given.center, read.center) < 1e-9 * domain.size
            assert abs(given.radius - read.radius) < 1e-9 * domain.size
            for p in (given.p0, given.p1):  # the arc runs through its own ends
                assert abs(math.dist(p, given.center) - given.radius) < 1e-12 * domain.size
    a, b = mesh_domain(domain), mesh_domain(again)
    assert (a.quality["quads"], a.quality["irregular_vertices"]) == \
        (b.quality["quads"], b.quality["irregular_vertices"])


def test_curve_ends_go_onto_the_vertices_their_cad_file_shares():
    # A CAD edge whose ends lie off the vertices it shares with its neighbours (a
    # kernel's vertex tolerance): moved there from beyond the gap tolerance (floor) up to
    # the limit, and the moves are returned for the report.
    pieces = [Line(np.array([0.0, 0.0]), np.array([5.0, 0.0])),
              (np.array([5.0, 0.0]), np.array([7.5, 1.0]), np.array([10.0, 0.01]))]
    moved, moves = onto_shared_vertices(pieces, [0.0, 0.02], [10.0, 0.0], 1e-3, 0.1)
    assert np.allclose(moved[0].p0, [0.0, 0.02]) and np.allclose(moved[0].p1, [5.0, 0.0])
    assert np.allclose(moved[-1][2], [10.0, 0.0]) and np.allclose(moved[-1][0], [5.0, 0.0])
    assert moves == pytest.approx([0.02, 0.01])
    assert "moved 2 curve end(s) onto the vertex" in vertex_note(0, moves)


def test_ends_far_off_or_within_the_gap_tolerance_stay_where_they_are():
    line = [Line(np.array([0.0, 0.0]), np.array([10.0, 0.0]))]
    far, far_moves = onto_shared_vertices(line, [0.0, 0.5], None, 1e-3, 0.1)
    near, near_moves = onto_shared_vertices(line, [0.0, 1e-4], None, 1e-3, 0.1)
    assert far_moves == [] and near_moves == []
    assert np.array_equal(far[0].p0, [0.0, 0.0]) and np.array_equal(near[0].p0, [0.0, 0.0])


def test_a_vertex_gap_past_the_limit_is_still_an_open_loop():
    # What is not moved is judged by validation as before: a real gap is refused.
    loop = [L([0, 0], [300, 0]), L([300, 0], [300, 200]), L([300, 200], [0, 200]),
            L([0, 200], [0, 0])]
    pieces = [Line(np.array(c["line"][0], float), np.array(c["line"][1], float)) for c in loop]
    size = math.hypot(300, 200)
    kept, moves = onto_shared_vertices(pieces[:1], [0.0, 0.0], [300.0, 5.0],
                                       HEAL_TOL * size, VERTEX_SNAP * size)
    assert moves == []
    with pytest.raises(DomainError, match=r"open loop"):
        make_domain([kept + [Line(np.array([300.0, 5.0]), np.array([300.0, 200.0]))]
                     + pieces[2:]])
