"""The real-part corpus (tests/corpus, see SOURCES.md): planar faces cut unrepaired out of
public CAD files, and faces of parts built in FreeCAD as a user would.  Every face is
imported as delivered (healing reported) or refused with a clear reason; each meshes
validly; a gmsh stand-in where blocks are expected is a failure, and the parts that still
get one are listed as strict expected failures, so a fix shows up and a regression too."""

from __future__ import annotations

import json
import time
from functools import cache
from pathlib import Path

import pytest

from quadcnn_wb.core.input.load import load_domain
from quadcnn_wb.core.mesh.orientation import tiles_exactly
from quadcnn_wb.core.mesh.validity import free_edges_on_boundary
from quadcnn_wb.core.pipeline import mesh_domain

CORPUS = Path(__file__).parent / "corpus"
PARTS = {entry["name"]: entry for entry in json.loads((CORPUS / "manifest.json").read_text())}

# Faces whose edges end off the vertices they share by more than healing's gap tolerance
# (see SOURCES.md): joined at those vertices, as the CAD kernel has them.
OFF_THEIR_VERTICES = {"ventilator_hub"}
# Partly in blocks: some faces of the partition get unstructured quads (free faces).
# (nist_ctc02_logo_plate and blend_scallop_slots were too, until blocks whose maps fold
# got lines across the fold, layout.cuts.fold_cuts: 0.75 and 0.86 of them in blocks; and
# nist_ctc01_logo_bracket, 0.934, until the round ends of the bays between its logo's
# strokes were read as square, input.features._convex_end.)
PARTLY_BLOCKS = {"blend_sawtooth"}
NO_BLOCKS_YET = PARTLY_BLOCKS
MESHABLE = list(PARTS)


def expected_failure(name: str, known: set, reason: str):
    return pytest.param(name, marks=pytest.mark.xfail(strict=True, reason=reason)) \
        if name in known else name


@cache
def meshed(name: str):
    return mesh_domain(load_domain(CORPUS / PARTS[name]["file"]))


def test_the_corpus_is_real():
    public = [n for n, e in PARTS.items() if e["kind"] == "public"]
    assert len(PARTS) >= 15 and len(public) >= 15
    assert all((CORPUS / e["file"]).is_file() for e in PARTS.values())
    sources = (CORPUS / "SOURCES.md").read_text()
    assert all(e["file"] in sources for e in PARTS.values())


@pytest.mark.parametrize("name", sorted(OFF_THEIR_VERTICES))
def test_edges_off_their_shared_vertices_are_joined_and_said_so(name):
    domain = load_domain(CORPUS / PARTS[name]["file"])
    assert any("onto the vertex they share" in note for note in domain.healed), domain.healed


@pytest.mark.parametrize("name", MESHABLE)
def test_every_other_face_imports_as_delivered(name):
    domain = load_domain(CORPUS / PARTS[name]["file"])
    assert domain.area > 0 and isinstance(domain.healed, tuple)


@pytest.mark.parametrize("name", MESHABLE)
def test_every_face_gets_a_valid_mesh(name):
    mesh = meshed(name).mesh
    assert meshed(name).quality["min_scaled_jacobian"] > 0
    assert tiles_exactly(mesh.nodes, mesh.quads)
    assert free_edges_on_boundary(mesh.quads, mesh.boundary)


@pytest.mark.parametrize("name", [expected_failure(n, NO_BLOCKS_YET, "no block partition")
                                  for n in MESHABLE])
def test_every_face_is_block_structured(name):
    result = meshed(name)
    assert result.structured_share == 1.0, result.problem
    # Irregular: the field's singular points, the corners small concave fillets are read
    # as (input.features: three quads where the boundary is smooth), and a few to spare.
    # (A small round hole's square has four such corners.)
    fillets = result.feature_corners
    assert result.quality["irregular_vertices"] <= \
        len(result.reference.field.singularities) + fillets \
        + max(4, KNOWN_EXTRA_IRREGULAR.get(name, 0))


# Irregular vertices besides the singular points and feature corners, where known:
# tailwheel_gusset's chamfer end (a 158° vertex with one quad), crank_arm_web's two
# kite corners (layout.cusps), sketch_keyhole_plate's pair at the keyhole's foot,
# nist_ctc04_plate's four (137 irregular vertices and worst 0.68 until collapses could
# no longer carry a vertex onto the boundary from most of an element away: 140 and 0.75;
# gmsh alg. 11 has 217 and 0.20);
# crankshaft_web_keyway's valence-3 and valence-5 vertices in the hub's two side bays
# (its 2048-node layout, all blocks since layout.wedges: worst scaled Jacobian 0.84
# against the finer layout's 0.71, which had none); blend_horn_square's kite corner at
# its horn's 0° tip; blend_slotted_plate's four, not yet told apart (its slots' round
# ends read as corners with four quads; 59 irregular vertices against gmsh's 179);
# perforated_plate's 29, where the lines of its 89 squared holes' corners end on each
# other (389 against gmsh's 786; all blocks at the default size since those lines leave
# straight along the squares' sides: 0.97 before); nist_ctc01_plate's two 270° notch
# corners, each with a valence-3 point an element off whose lens (layout.lenses) became one
# line: the corner has two quads where its angle asks three, the point is regular (its
# 2048-node layout is all blocks since: 62 irregular vertices and worst 0.86 against the
# 8192-node layout's 60 and 0.85, in 0.6 s against 1.4 s); blend_pocket_kink's 225° kink,
# which takes three quads where DESIGN.md's round() says two (input.corners.odd_ties:
# no singular point), and a line of the kink's that ends in the outer corner under a wall
# a fifth of an element thick, a valence-3 point beside it (gmsh alg. 11: 46, and folds);
# blend_scallop_slots' one, since lines across its folding blocks made it all blocks
# (16 irregular vertices against 10 singular points and 5 feature corners; gmsh: 40);
# fsr_sensor_clamp's two 135° chamfer corners at the ends of its C (one quad each, the
# two quarter turns its 35.5° tips leave: no singular point; gmsh alg. 11: 18);
# nist_ctc01_logo_bracket's one, the valence-3 middle of the three-cornered bay between
# its "N"'s diagonal and right stroke, where the field has no singular point (16 against
# 1 singular point and 14 feature corners; gmsh alg. 11: 84, and folds);
# soarm_bow_tie_pocket's two, the valence-3 middles of its two right triangles, whose
# field is real and has no singular point (framefield.triangle_windings; gmsh: 8);
# soarm_teardrop_slot's one, the 135° corner where its chamfer meets the cusp's tangent
# arc, one quad where DESIGN.md's count asks two (gmsh: 47, and folds).
KNOWN_EXTRA_IRREGULAR = {"tailwheel_gusset": 1, "crank_arm_web": 2, "sketch_keyhole_plate": 2,
                         "nist_ctc01_logo_bracket": 1, "soarm_bow_tie_pocket": 2,
                         "soarm_teardrop_slot": 1, "blend_pocket_kink": 3,
                         "blend_scallop_slots": 1,
                         "nist_ctc04_plate": 4, "nist_ctc01_plate": 2,
                         "crankshaft_web_keyway": 2, "blend_horn_square": 1,
                         "blend_slotted_plate": 4, "perforated_plate": 29,
                         "fsr_sensor_clamp": 2}


@pytest.mark.parametrize("name", [n for n in MESHABLE if n not in PARTLY_BLOCKS])
def test_the_irregular_vertices_are_the_fields_own(name):
    # Tighter than the bound above (four to spare), which let grabcad_misc_part1 go from
    # 8 to 12 (a line read as arriving along the wrong separatrix of a window corner).
    result = meshed(name)
    own = len(result.reference.field.singularities) + result.feature_corners
    extra = result.quality["irregular_vertices"] - own
    # Fewer is allowed: a feature corner whose quads happen to be as many as its angle
    # asks is no irregular vertex (grabcad_part19: 44 against 20 singular points and 28
    # feature corners).
    assert extra <= KNOWN_EXTRA_IRREGULAR.get(name, 0)


# At the second size of the corpus benchmark (bench.corpus: diameter / 100).  Not
# perforated_plate: 100 s there (the benchmark command measures it).
FINE_TOO_SLOW = {"perforated_plate"}
# All in blocks there, with irregular vertices beyond the singular points and feature
# corners and the four to spare (nist_ctc04_plate 144 against 140, grabcad_part19 16
# against 12; gmsh alg. 11 has 387 and 144).
FINE_EXTRA_IRREGULAR = {"nist_ctc04_plate", "grabcad_part19"}
# Free faces there too (blend_sawtooth: 0.62 of it in blocks).  nist_ctc02_logo_plate and
# nist_ctc01_logo_bracket (0.994 and 0.981) were all blocks on the third background try
# (pipeline.finest_background_nodes), and on the first since their logos' narrow bays got
# square ends; perforated_plate is all blocks on the third (0.983: 100 s, not here).
FINE_PARTLY_BLOCKS = {"blend_sawtooth"}


@pytest.mark.parametrize("name", [
    expected_failure(n, FINE_EXTRA_IRREGULAR | FINE_PARTLY_BLOCKS,
                     "free faces or irregular vertices the field does not have")
    for n in MESHABLE if n not in FINE_TOO_SLOW])
def test_every_face_is_block_structured_at_a_hundredth_of_its_diameter(name):
    from quadcnn_wb.core.input.pose import diameter

    domain = load_domain(CORPUS / PARTS[name]["file"])
    result = mesh_domain(domain, size=diameter(domain) / 100)
    assert result.structured_share == 1.0, result.problem
    assert result.quality["min_scaled_jacobian"] > 0
    assert tiles_exactly(result.mesh.nodes, result.mesh.quads)
    assert result.quality["irregular_vertices"] <= \
        len(result.reference.field.singularities) + result.feature_corners + 4


def test_the_logo_plate_falls_back_as_a_whole_without_finer_fills(monkeypatch):
    # What the finer fills rescue: without them every line round the logo is dissolved.
    from quadcnn_wb.core import pipeline, rounds

    # (Lines across folding blocks, layout.cuts.fold_cuts, make it all blocks now; without
    # them the finer fills are what is left.)
    monkeypatch.setattr(rounds, "FOLD_CUT_ROUNDS", 0)
    monkeypatch.setattr(pipeline, "FINER_BACKGROUND", 1)
    domain = load_domain(CORPUS / PARTS["nist_ctc02_logo_plate"]["file"])
    filled = mesh_domain(domain)
    assert 0.5 < filled.structured_share < 1.0, filled.problem
    monkeypatch.setattr(pipeline, "_with_finer_fills", lambda *args: None)
    result = mesh_domain(domain)
    assert not result.structured and "stand in" in result.problem
    assert result.structured_share == 0.0


def test_a_face_without_blocks_says_so(monkeypatch):
    # No corpus face falls back as a whole any more; with no rebuild allowed, the free
    # faces of blend_scallop_slots that cannot be filled on the 2048-node background (and
    # no finer one allowed) leave no block partition, and the quads that stand in (gmsh's,
    # or the whole face as one free face where those fold) must say so everywhere.
    # (nist_ctc04_plate did so until its small holes' corner lines left straight along
    # the squares' sides: then only one face of 190 was no block.)
    from quadcnn_wb.core import pipeline, rounds

    monkeypatch.setattr(rounds, "FREEING_ROUNDS", 0)
    monkeypatch.setattr(pipeline, "FINER_BACKGROUND", 1)
    result = mesh_domain(load_domain(CORPUS / PARTS["blend_scallop_slots"]["file"]))
    assert not result.structured and "no block structure" in result.problem
    assert "stand in" in result.problem and result.quality["min_scaled_jacobian"] > 0
    data = result.to_json()
    assert data["structured"] is False and data["structured_share"] == 0.0
    assert data["problem"] == result.problem


@pytest.mark.parametrize("name", sorted(PARTLY_BLOCKS))
def test_faces_that_are_no_blocks_cost_only_themselves(name):
    result = meshed(name)
    assert 0.0 < result.structured_share < 1.0, result.problem
    assert "unstructured quads there" in result.problem
    assert result.partition.free_faces and result.partition.blocks
    assert result.to_json()["structured_share"] == result.structured_share


# housing_rib: free faces; io1_flange: full circles only (its pose once hung on a bore
# concentric with the centroid); socket_bearing: blocks only; sketch_gasket: symmetric,
# so round-off split its field's zeros differently in every pose until the field was
# solved in the canonical pose; sketch_bracket: its mirror image got another layout (a
# zero fitted outside its triangle was clamped from the triangle's first corner, and a
# separatrix swung onto its neighbour's arm); tailwheel_gusset: a cancelling pair;
# sketch_keyhole_plate and sketch_tslot_profile: 135° and 225° corners, exactly between
# two quad counts (the field wound at them as round-off had it, seeding singular points);
# motor_c_plate, sketch_gear and engine_top: steps and fillets below the element size
# (input.features; the gear's root fillets and engine_top's are concave corners at the
# default size, and a mirrored copy must read each stretch the same way round);
# nist_ctc01_plate and anc101_flange: bolt holes read as squares (input.small_holes),
# whose corners a turned or mirrored copy must place alike; crankshaft_web_keyway and
# bracket_plate: slot ends read as corners, placed alike in every pose; grabcad_part19
# and nist_ctc04_plate: short boundary arcs with no segment (the merged node on the
# corner or half-way), and no vertex carried most of an element onto the boundary; nist_ctc04's
# mirror image got other counts (177 blocks and 381 quads against 179 and 361) while
# its edges were measured by chords and the merges refused to a pinch were found along
# links in the pose's node order; blend_plate_hole: a separatrix ended on the singular
# point it passes (field_rules: measured along the lines, alike in every pose);
# blend_horn_plate: its horns' tips read 0° or 360° and their tip quads flat or not as
# round-off had it in each pose (input.corners, rounds.TIP_JACOBIAN); blend_sawtooth:
# the line moved off a wedge at a tooth's root was the first in the traces' order, which
# a mirror image reverses (layout.wedges); blend_scallop_slots: a corner's trace of no
# length took a separatrix's slot, flat fill quads read 0 or +-1e-17, tied smoothing
# moves went to the first in a compass a mirror image reverses, and which of two lines
# side by side lost its edge followed the traces' numbering; nist_ctc01_logo_bracket: a
# node slid along two boundary arcs of one length sat on the middle of whichever
# round-off made the longer (quadmesh._place_slid_nodes: half-way along the run);
# blend_pocket_kink: its 225° tie takes three quads (input.corners.odd_ties) in every pose;
# nist_ctc01_letters: lines across folding blocks start from the boundary node nearest
# the fold, which every pose must find alike; soarm_bow_tie_pocket: symmetric, its field
# real, zero along a curve whose triangles the wrap read as zeros all one way.
# Moved by 1e4 of its size, blend_sawtooth's coordinates (1.6e6) hold its teeth's
# smallest quads (edges of 2e-5 of its size) to about 1e-7 of their size, past the 1e-9
# that the max-min moves compare at: meshed in its own coordinates every layout fell
# back.  The whole pipeline now runs in the part's frame (core.layout_frame).


PART_POSES = ((37.0, False, 1.0, 0.0), (0.0, False, 1.0, 1e4), (211.0, True, 1.0, 0.0),
              (131.0, False, 1e-3, 3.0))
# The slowest parts (5 to 9 s a mesh), in two poses each: those that once gave
# sawtooth another mesh, the mirror and the rescaled, moved turn for nist_ctc04_plate,
# the odd turn and the mirror for sketch_gear.  The suite's time (near its 15 minutes),
# not the other poses' worth, leaves them out.
SLOW_PART_POSES = {"blend_sawtooth": PART_POSES[1:3],
                   "nist_ctc04_plate": PART_POSES[2:4],
                   "sketch_gear": (PART_POSES[0], PART_POSES[2])}


@pytest.mark.parametrize("name", ["housing_rib", "io1_flange", "socket_bearing",
                                  "sketch_gasket", "sketch_bracket", "tailwheel_gusset",
                                  "sketch_keyhole_plate", "sketch_tslot_profile",
                                  "motor_c_plate", "sketch_gear", "engine_top",
                                  "nist_ctc01_plate", "anc101_flange",
                                  "crankshaft_web_keyway", "bracket_plate",
                                  "grabcad_part19", "nist_ctc04_plate",
                                  "blend_plate_hole", "blend_horn_plate",
                                  "blend_sawtooth", "occt_face2",
                                  "blend_scallop_slots", "nist_ctc01_logo_bracket",
                                  "blend_pocket_kink", "nist_ctc01_letters",
                                  "fsr_sensor_clamp", "soarm_bow_tie_pocket",
                                  "soarm_teardrop_slot"])
def test_a_part_gets_the_same_mesh_in_every_pose(name):
    import numpy as np

    from quadcnn_wb.core.input.domain import domain_from_json
    from quadcnn_wb.core.input.transform import similarity, transform_domain_json

    data = load_domain(CORPUS / PARTS[name]["file"]).to_json()
    base = mesh_domain(domain_from_json(data))
    assert base.structured_share > 0.0

    def signature(r):
        q = r.quality
        return round(r.structured_share, 9), q["blocks"], q["quads"], q["irregular_vertices"]

    size = base.domain.size
    for degrees, mirror, scale, shift in SLOW_PART_POSES.get(name, PART_POSES):
        moved = transform_domain_json(data, similarity(degrees, scale, mirror),
                                      np.full(2, shift * size * scale))
        assert signature(mesh_domain(domain_from_json(moved))) == signature(base), degrees


POSES = ((37.0, False, 1.0, 0.0), (0.0, False, 1.0, 1e4), (211.0, True, 1.0, 0.0),
         (131.0, False, 1e-3, 3.0), (0.0, False, 1e3, 0.0))


@pytest.mark.parametrize("name", MESHABLE)
def test_every_part_is_accepted_in_every_pose(name):
    # Validation must not hang on round-off: sketch_gasket moved by 1e4 of its size had a
    # hole "outside" its outer loop (a probe point on the chord of a boss's arc).
    import numpy as np

    from quadcnn_wb.core.input.domain import domain_from_json
    from quadcnn_wb.core.input.transform import similarity, transform_domain_json

    domain = load_domain(CORPUS / PARTS[name]["file"])
    data = domain.to_json()
    for degrees, mirror, scale, shift in POSES:
        moved = transform_domain_json(data, similarity(degrees, scale, mirror),
                                      np.full(2, shift * domain.size * scale))
        assert len(domain_from_json(moved).loops) == len(domain.loops), (degrees, shift)


def test_a_part_whose_features_the_background_misses_is_laid_out_on_a_finer_one(monkeypatch):
    # sketch_gear: on 2048 background nodes the field does not resolve all its roots
    # (a six-cornered face above the keyway, which only a cut makes blocks: two extra
    # irregular vertices and a worst element of 0.66); on four times as many the whole
    # face is blocks, irregular only at its roots' corners (its root fillets, read as
    # concave corners), and its worst element 0.75.
    from quadcnn_wb.core import pipeline

    domain = load_domain(CORPUS / PARTS["sketch_gear"]["file"])
    monkeypatch.setattr(pipeline, "FINER_BACKGROUND", 1)
    coarse = mesh_domain(domain)
    assert coarse.quality["irregular_vertices"] > \
        len(coarse.reference.field.singularities) + coarse.feature_corners
    monkeypatch.setattr(pipeline, "FINER_BACKGROUND", 4)
    finer = mesh_domain(domain)
    assert finer.structured_share == 1.0, finer.problem
    assert finer.reference.mesh.n_nodes > 3 * coarse.reference.mesh.n_nodes
    corners = finer.feature_corners
    assert finer.quality["irregular_vertices"] <= \
        len(finer.reference.field.singularities) + corners
    assert finer.timings["total"] >= finer.timings["other_background"] > 0
    assert finer.quality["min_scaled_jacobian"] > coarse.quality["min_scaled_jacobian"]


@pytest.mark.parametrize("name, divisor, finished, good_enough", [
    ("sketch_keyhole_plate", None, [8192], None),
    ("nist_ctc04_plate", None, [8192, 2048], (1.01, 0.2)),
    ("nist_ctc04_plate", None, [8192], None)])
def test_a_first_layout_with_free_faces_is_finished_only_if_the_finer_one_has_some(
        monkeypatch, name, divisor, finished, good_enough):
    # The freeing rounds and unstructured fills of a layout that leaves free faces cost
    # more than the finer try (nist_ctc01_plate: 3.5 s against 0.8 s, before its first
    # layout was all blocks), so they wait for it: sketch_keyhole_plate's and
    # nist_ctc04_plate's finer layouts are all blocks.  No
    # corpus part's finer layout is under GOOD_ENOUGH any more; asked for more than all
    # blocks, nist_ctc04_plate's first layout is finished too (from its own streamlines).
    from quadcnn_wb.core import pipeline, rounds
    from quadcnn_wb.core.input.pose import diameter

    if good_enough is not None:
        monkeypatch.setattr(pipeline, "GOOD_ENOUGH", good_enough[0])
        monkeypatch.setattr(rounds, "FAIR_JACOBIAN", good_enough[1])

    calls, reused = [], []
    real = pipeline._mesh_on_background

    def counted(domain, size, nodes, *args, stop_at_free=False, traced=None):
        try:
            result = real(domain, size, nodes, *args, stop_at_free=stop_at_free,
                          traced=traced)
        except pipeline.LeavesFreeFaces:
            calls.append(("stopped", nodes))
            raise
        calls.append(("finished", nodes))
        reused.append(traced is not None)
        return result

    monkeypatch.setattr(pipeline, "_mesh_on_background", counted)
    domain = load_domain(CORPUS / PARTS[name]["file"])
    clock = time.perf_counter()
    result = mesh_domain(domain, size=None if divisor is None else diameter(domain) / divisor)
    wall = time.perf_counter() - clock
    # The reported total holds both layouts' every stage (the stopped one's background,
    # field and traces were once left out: 0.9 s of nist_ctc04_plate's 4.9).
    assert result.timings["total"] > 0.85 * wall
    assert calls[0] == ("stopped", 2048)
    assert [n for what, n in calls[1:] if what == "finished"] == finished
    assert len(calls) == 1 + len(finished)
    # The stopped layout is finished from the streamlines it traced, the finer one fresh.
    assert reused == [n == 2048 for n in finished]
    assert result.timings["other_background"] > 0


def test_two_lines_round_a_thin_lens_become_one():
    # grabcad_part19's bosses: two traces meet on the same stretch and bound a lens half
    # an element wide (rounds._twin_lines); with one of them gone its 2048-node layout
    # is all blocks, so the finer one is not tried (it had 56 irregular vertices).
    result = meshed("grabcad_part19")
    assert result.structured_share == 1.0 and "other_background" not in result.timings
    assert result.reference.mesh.n_nodes < 2 * 2048


def test_the_finer_background_is_skipped_when_it_would_not_fit_the_time_allowed():
    # The command line's --time-limit is a hard ceiling: a second layout that cannot fit
    # in it is not started (perforated_plate took 174 s with it, over the default 120 s).
    domain = load_domain(CORPUS / PARTS["nist_ctc04_plate"]["file"])
    result = mesh_domain(domain, seconds=1e-3)
    assert result.structured_share < 1.0 and "other_background" not in result.timings
    assert result.reference.mesh.n_nodes < 2 * 2048  # the first background, not 4x it


def test_a_thin_spike_is_one_column_of_quads_as_good_as_its_tip_allows():
    """tailwheel_gusset's spike (1 mm wide, a 0.35 mm chamfer at its tip) is a three-
    cornered face: it gets its fourth corner at the chamfer's upper end, so the worst
    quad there has the boundary's own angle (gmsh's best), not three blocks squeezed
    round an extra irregular vertex (0.25)."""
    import numpy as np

    result = meshed("tailwheel_gusset")
    outer = result.domain.loops[0]
    ends = [k for k in range(len(outer))
            if np.allclose(outer[k].p1, [-32.26763784, 1.00433975], atol=1e-6)]
    assert len(ends) == 1
    a, b = outer[ends[0]].tangent(1.0), outer[(ends[0] + 1) % len(outer)].tangent(0.0)
    bend_sine = abs(a[0] * b[1] - a[1] * b[0]) / np.hypot(*a) / np.hypot(*b)
    assert result.structured_share == 1.0
    assert result.quality["min_scaled_jacobian"] >= bend_sine - 1e-9
    # Irregular: the singular points, the small concave fillet read as a corner, and the
    # chamfer's end, a 158° vertex with the one quad of a block corner.
    # (A small round hole's square has four such corners.)
    fillets = result.feature_corners
    assert result.quality["irregular_vertices"] == \
        len(result.reference.field.singularities) + fillets + 1
    mesh = result.mesh
    at_end = np.nonzero(np.hypot(*(mesh.nodes - outer[ends[0]].p1).T) < 1e-9)[0]
    assert len(at_end) == 1 and np.sum(mesh.quads == at_end[0]) == 1


@pytest.mark.parametrize("divisor", [None, 100])
def test_a_cusp_tip_is_one_quad_at_the_end_of_a_kite(divisor):
    """crank_arm_web's horns end in cusps of 1.4° and 1.9° (tangent curves), and the
    valence-5 point beside each sends a separatrix into the tip (layout.cusps): the tip
    holds one quad, the kite's inner corner is a valence-3 vertex one element short of
    the tip, and the whole face is blocks (before: two quads at each tip and four faces of
    unstructured quads at the default size)."""
    import numpy as np

    from quadcnn_wb.core.input.corners import interior_angle
    from quadcnn_wb.core.input.pose import diameter

    domain = load_domain(CORPUS / PARTS["crank_arm_web"]["file"])
    result = meshed("crank_arm_web") if divisor is None \
        else mesh_domain(domain, size=diameter(domain) / divisor)
    loop = domain.loops[0]
    tips = [loop[k].p1 for k in range(len(loop))
            if np.degrees(interior_angle(loop[k], loop[(k + 1) % len(loop)])) < 5]
    assert len(tips) == 2
    assert result.structured_share == 1.0, result.problem
    mesh = result.mesh
    for tip in tips:
        node = np.nonzero(np.hypot(*(mesh.nodes - tip).T) < 1e-9)[0]
        assert len(node) == 1 and np.sum(mesh.quads == node[0]) == 1
        (quad,) = np.nonzero((mesh.quads == node[0]).any(axis=1))[0]
        opposite = mesh.quads[quad][(list(mesh.quads[quad]).index(node[0]) + 2) % 4]
        assert np.sum(mesh.quads == opposite) == 3
    assert result.quality["irregular_vertices"] <= \
        len(result.reference.field.singularities) + len(tips)


def test_blocks_given_up_once_are_not_posed_to_the_program_again(monkeypatch):
    # grabcad_part19 at its diameter / 40 on 2048 background nodes: the freeing rounds
    # rebuild the partition; a block whose sides no counts balance (two at a boss) is
    # given up before the next round's program (which is slow while it may give blocks
    # up), so no round returns one an earlier round did.  The counts balance there since
    # a short boundary arc may have none (a trace that ended beside a corner); with every
    # boundary arc held to one segment, as before, two blocks are given up.
    from quadcnn_wb.core import pipeline
    from quadcnn_wb.core import rounds as layout_rounds
    from quadcnn_wb.core.input.pose import diameter
    from quadcnn_wb.core.input.small_holes import squared_holes
    from quadcnn_wb.core.layout import quantize

    rounds = []
    real = layout_rounds.quantize_freeing

    def recorded(partition, size):
        counts, unequal = real(partition, size)
        rounds.append({layout_rounds._block_key(partition, b) for b in unequal})
        return counts, unequal

    monkeypatch.setattr(layout_rounds, "quantize_freeing", recorded)
    monkeypatch.setattr(quantize, "SHORT_BOUNDARY_ARC", -1.0)
    domain = load_domain(CORPUS / PARTS["grabcad_part19"]["file"])
    size = diameter(domain) / 40
    result = pipeline._mesh_on_background(squared_holes(domain, size), size, 2048,
                                          "numerical", True, None)
    assert len(rounds) > 1 and rounds[0]
    for k in range(1, len(rounds)):
        assert not rounds[k] & set().union(*rounds[:k])
    assert 0.0 < result.structured_share < 1.0


def test_blocks_whose_counts_cannot_balance_are_found_as_the_exact_program_finds_them(
        monkeypatch):
    """The program that may give up any block is exact but slow on big partitions (it ran
    past its minute on perforated_plate's 1000 blocks, so that layout was lost); the
    elastic rounds name the blocks left unequal in a fraction of a second and the exact
    program then chooses among those and their neighbours only.  On grabcad_part19 (as
    in the test above) it gives up the very blocks the unrestricted program does, and
    every other block balances."""
    from quadcnn_wb.core import pipeline, rounds
    from quadcnn_wb.core.input.pose import diameter
    from quadcnn_wb.core.input.small_holes import squared_holes
    from quadcnn_wb.core.layout import quantize

    posed = []
    real = rounds.quantize_freeing

    def recorded(partition, size):
        posed.append((partition, size))
        return real(partition, size)

    monkeypatch.setattr(rounds, "quantize_freeing", recorded)
    monkeypatch.setattr(quantize, "SHORT_BOUNDARY_ARC", -1.0)
    domain = load_domain(CORPUS / PARTS["grabcad_part19"]["file"])
    size = diameter(domain) / 40
    pipeline._mesh_on_background(squared_holes(domain, size), size, 2048, "numerical", True,
                                 None)
    partition, size = posed[0]
    with pytest.raises(quantize.InfeasibleCounts):
        quantize.quantize(partition, size)
    counts, given_up = real(partition, size)
    _, exact = quantize._solve(partition, size, quantize.MILP_SECONDS, free_blocks=True)
    assert given_up and given_up == exact
    sides = quantize.side_counts(partition, counts)
    for b in set(range(len(partition.blocks))) - set(given_up):
        assert sides[b][0] == sides[b][2] and sides[b][1] == sides[b][3]


def _first_partition(name, nodes=2048):
    """The first partition the pipeline poses to the segment-count program for a corpus
    part at its default size, on ``nodes`` background nodes."""
    from quadcnn_wb.core import pipeline, rounds
    from quadcnn_wb.core.input.pose import default_size
    from quadcnn_wb.core.input.small_holes import squared_holes

    posed = []

    class Posed(Exception):
        pass

    def record(partition, size):
        posed.append((partition, size))
        raise Posed

    domain = load_domain(CORPUS / PARTS[name]["file"])
    size = default_size(domain)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(rounds, "quantize_freeing", record)
        with pytest.raises(Posed):
            pipeline._mesh_on_background(squared_holes(domain, size), size, nodes,
                                         "numerical", True, None)
    return posed[0]


def test_counts_that_pinch_in_every_balanced_solution_give_up_a_block_near_the_pinch():
    """nist_ctc04_plate's 2048-node layout: every block's sides balance (the elastic
    program leaves none unequal), but every balanced solution merges two anchors, so the
    program with every block kept is infeasible once the rows against pinches are in.
    Those rows come with the refusal, and the program that may give blocks up starts from
    them and chooses among the blocks they name and their neighbours (6 s, where the one
    that may give up any of the 189 took 19 s): it gives up as few as the unrestricted
    program, and every other block balances."""
    from quadcnn_wb.core.layout import quantize

    partition, size = _first_partition("nist_ctc04_plate")
    with pytest.raises(quantize.InfeasibleCounts) as refused:
        quantize.quantize(partition, size)
    assert refused.value.forbidden
    assert quantize._unequal_blocks(partition, size, quantize.MILP_SECONDS) == []
    counts, given_up = quantize.quantize_freeing(partition, size)
    assert 0 < len(given_up) < 3
    assert given_up and set(given_up) <= quantize._with_neighbours(
        partition, quantize.blocks_on(partition, refused.value.edges))
    sides = quantize.side_counts(partition, counts)
    for b in set(range(len(partition.blocks))) - set(given_up):
        assert sides[b][0] == sides[b][2] and sides[b][1] == sides[b][3]


def test_a_first_layout_that_must_give_a_block_up_stops_before_choosing_which(monkeypatch):
    """The race to a finer background (pipeline._best_layout) wants to know only whether
    the first layout leaves free faces; choosing which blocks to give up is the slow
    program, so it is not posed (nist_ctc04_plate at its default size: 2 s in all, 22.8 s
    when it was)."""
    from quadcnn_wb.core import pipeline, rounds
    from quadcnn_wb.core.input.pose import default_size
    from quadcnn_wb.core.input.small_holes import squared_holes

    def refuse(partition, size):
        raise AssertionError("the program that gives blocks up was posed")

    monkeypatch.setattr(rounds, "quantize_freeing", refuse)
    domain = load_domain(CORPUS / PARTS["nist_ctc04_plate"]["file"])
    size = default_size(domain)
    with pytest.raises(pipeline.LeavesFreeFaces):
        pipeline._mesh_on_background(squared_holes(domain, size), size, 2048, "numerical",
                                     True, None, stop_at_free=True)
    monkeypatch.undo()  # the finer layout, all in blocks, poses it as it should
    result = mesh_domain(domain)
    assert result.structured_share == 1.0 and result.quality["min_scaled_jacobian"] > 0.8


@pytest.mark.parametrize("divisor", [None, 100])
def test_a_separatrix_into_a_notch_corner_keeps_its_corners(divisor):
    """sketch_tslot_profile: where each 45° arm meets its flange (a 225° notch) the
    separatrix of the valence-5 point beside it leaves the domain 0.3 sizes short of the
    corner and is moved onto it.  Moved by its last point alone it came in with a kink,
    the face beside it measured a 22° turn there and lost its corner: a three-cornered
    face, split round an extra valence-3 vertex, and a third quad at the notch (24
    irregular vertices for 16 singular points).  Bent smoothly onto the corner, every
    irregular vertex is a singular point."""
    from quadcnn_wb.core.input.pose import diameter

    domain = load_domain(CORPUS / PARTS["sketch_tslot_profile"]["file"])
    result = meshed("sketch_tslot_profile") if divisor is None \
        else mesh_domain(domain, size=diameter(domain) / divisor)
    assert result.structured_share == 1.0, result.problem
    assert result.quality["irregular_vertices"] == \
        len(result.reference.field.singularities) + result.feature_corners
