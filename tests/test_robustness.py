"""Robustness: a moved, turned, mirrored or rescaled part gets the transformed mesh; the same
input gives the same mesh; random shapes mesh validly (independent checker) or are refused
with a reason; bad input on the command line is one error line and leaves no file; no run
outlives its time limit."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import SHARED_EXAMPLES, run_cli
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree

from quadcnn_wb.bench.robustness import NEVER, campaign, report, run_one
from quadcnn_wb.core.input.domain import domain_from_json
from quadcnn_wb.core.input.pose import area_centroid
from quadcnn_wb.core.input.transform import similarity, transform_domain_json
from quadcnn_wb.core.pipeline import mesh_domain

POSES = {
    "moved": (similarity(0.0), (123.25, -77.5)),
    "turned 30°": (similarity(30.0), (0.0, 0.0)),
    "turned 90° and moved": (similarity(90.0), (5.0, 5.0)),
    "mirrored": (similarity(0.0, mirror=True), (0.0, 0.0)),
    "1 µm part": (similarity(200.0, scale=1e-6), (1e-6, 0.0)),
    "100 km part": (similarity(-60.0, scale=1e8), (3e8, -1e8)),
}


@pytest.fixture(scope="module")
def reference_meshes():
    cache = {}

    def get(name):
        if name not in cache:
            data = json.loads((SHARED_EXAMPLES / f"{name}.json").read_text())
            cache[name] = (data, mesh_domain(domain_from_json(data)))
        return cache[name]
    return get


@pytest.mark.parametrize("pose", POSES)
@pytest.mark.parametrize("name", ["plate_hole", "concave", "semicircle"])
def test_transformed_input_gives_the_transformed_mesh(reference_meshes, name, pose):
    data, base = reference_meshes(name)
    matrix, shift = POSES[pose]
    moved = mesh_domain(domain_from_json(transform_domain_json(data, matrix, shift)))
    for key in ("quads", "blocks", "irregular_vertices"):
        assert moved.quality[key] == base.quality[key], key
    for key in ("min_scaled_jacobian", "mean_scaled_jacobian"):
        assert moved.quality[key] == pytest.approx(base.quality[key], rel=1e-9), key
    # The nodes, mapped back, are the base mesh's nodes, or (for a symmetric part, where
    # the pose cannot tell mirror images apart) their image under the part's symmetry:
    # their distances from the part's centroid agree either way.
    back = (moved.mesh.nodes - shift) @ np.linalg.inv(matrix).T
    centre = area_centroid(base.domain)
    radii = [np.sort(np.hypot(*(nodes - centre).T)) for nodes in (back, base.mesh.nodes)]
    assert np.abs(radii[0] - radii[1]).max() <= 1e-9 * base.domain.size
    if pose != "mirrored":
        distance, _ = cKDTree(base.mesh.nodes).query(back)
        assert distance.max() <= 1e-9 * base.domain.size


def test_same_input_same_mesh(reference_meshes):
    data, base = reference_meshes("plate_hole")
    again = mesh_domain(domain_from_json(data))
    assert np.array_equal(again.mesh.nodes, base.mesh.nodes)
    assert np.array_equal(again.mesh.quads, base.mesh.quads)


@settings(max_examples=6, derandomize=True, deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(min_value=0, max_value=2**31 - 1))
def test_random_shapes_mesh_validly_or_are_refused(index):
    row = run_one(seed=20261122, index=index)
    assert row["outcome"] not in NEVER, row
    if row["outcome"] == "refused":
        assert row["reason"]  # a reason the user can act on
    else:
        assert row["quads"] > 0 and row["min_sj"] > 0


def test_campaign_runs_in_workers_and_reports():
    rows = campaign(4, seed=7, workers=2, timeout=120, progress=False)
    assert [r["index"] for r in rows] == [0, 1, 2, 3]
    assert not [r for r in rows if r["outcome"] in NEVER]
    text = report(rows)
    assert text.startswith("4 random shapes") and "must-never outcomes" in text


BAD_INPUTS = {
    "empty.json": (b"", "empty"),
    "array.json": (b"[1, 2, 3]", "must be an object"),
    "null.json": (b"null", "must be an object"),
    "garbage.json": (b"{not json", "not valid JSON"),
    "noloops.json": (b'{"units": "mm"}', "loops"),
    "empty.step": (b"", "empty"),
    "truncated.step": (b"ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');", "STEP"),
}


@pytest.mark.parametrize("name", BAD_INPUTS)
def test_bad_input_files_exit_2_and_leave_no_file(tmp_path, name):
    content, message = BAD_INPUTS[name]
    (tmp_path / name).write_bytes(content)
    out = tmp_path / "mesh.json"
    result = run_cli("mesh", tmp_path / name, "-o", out, "--png", tmp_path / "mesh.png")
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), result.stderr
    assert message.lower() in lines[0].lower(), lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]


@pytest.mark.parametrize("model, message", [
    ("missing.onnx", "no such model file"),
    ("corrupt.onnx", "not a readable ONNX model"),
])
def test_bad_model_files_exit_2(tmp_path, model, message):
    (tmp_path / "corrupt.onnx").write_bytes(b"\x08\x01garbage")
    out = tmp_path / "mesh.json"
    out.write_text("earlier result")
    result = run_cli("mesh", SHARED_EXAMPLES / "l_shape.json", "--model", tmp_path / model,
                     "-o", out)
    assert result.returncode == 2 and message in result.stderr
    assert out.read_text() == "earlier result"  # a failed run loses nothing


def test_time_limit_is_a_clear_error_and_leaves_no_file(tmp_path):
    out = tmp_path / "mesh.json"
    result = run_cli("mesh", SHARED_EXAMPLES / "four_hole.json", "--nodes", "20000",
                     "--time-limit", "0.2", "-o", out)
    assert result.returncode == 2
    assert result.stderr.startswith("error: gave up after 0.2 s"), result.stderr
    assert not out.exists()


def test_family_benchmark_meshes_fresh_members_and_reports():
    from quadcnn_wb.bench.families import report, run_member

    rows = [run_member(name, 5, 0) for name in ("l_shape", "four_hole")]
    assert all(r["structured"] and r["valid"] and r["share"] == 1.0 for r in rows), rows
    assert all(r["extra_irregular"] == 0 for r in rows)
    text = report(rows)
    assert text.splitlines()[0].startswith("family") and "four_hole" in text
