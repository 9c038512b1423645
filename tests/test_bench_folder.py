"""The folder benchmark: every part of a folder in its own process, rows kept and compared."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys

from conftest import REPO


def run_folder(*args):
    return subprocess.run([sys.executable, "-m", "quadcnn_wb.bench.folder", *map(str, args)],
                          capture_output=True, text=True, timeout=600, cwd=REPO)


def test_a_folder_is_meshed_file_by_file_and_compared_with_an_earlier_run(tmp_path):
    parts = tmp_path / "parts"
    parts.mkdir()
    shutil.copy(REPO / "resources" / "examples" / "l_shape.json", parts / "l_shape.json")
    (parts / "open.json").write_text(json.dumps(
        {"loops": [[{"line": [[0, 0], [1, 0]]}, {"line": [[1, 0], [1, 1]]}]]}))
    (parts / "notes.txt").write_text("not a part")
    (parts / "manifest.json").write_text(json.dumps({"l_shape": {"source": "bundled"}}))
    # A list, as tests/corpus/manifest.json is: no part either.
    (parts / "sources.json").write_text(json.dumps([{"name": "l_shape", "file": "x"}]))
    (parts / "broken.json").write_text('{"loops": [')
    rows = tmp_path / "rows.jsonl"
    run = run_folder(parts, "--rows", rows, "--time-limit", 300)
    assert run.returncode == 0, run.stderr
    assert "skipped (JSON of something else: no 'loops'): manifest.json, sources.json" \
        in run.stdout
    written = [json.loads(line) for line in rows.read_text().splitlines()]
    assert {(r["name"], r["size_kind"]) for r in written} == {
        ("l_shape", "default"), ("l_shape", "d100"), ("open", "default"), ("open", "d100"),
        ("broken", "default"), ("broken", "d100")}
    good = [r for r in written if r["name"] == "l_shape"]
    assert all(r["structured_share"] == 1.0 and r["quads"] > 0 for r in good)
    # An L-shape's quads are about the size asked for: none over twice it, none under.
    assert all(1.0 <= r["longest_edge"] < 2.0 for r in good)
    assert not any("problem" in r for r in good)  # only rows with free faces say why
    assert all("open loop" in r["error"] for r in written if r["name"] == "open")
    assert all(r["error"] for r in written if r["name"] == "broken")  # a corrupt part
    assert "default: all in blocks 1/3 (2 errors)" in run.stdout

    again = run_folder(parts, "--names", "l_shape", "--compare", rows)
    assert again.returncode == 0, again.stderr
    assert "0 rows differ" in again.stdout  # the same input gives the same mesh


def run_on_one_part(tmp_path, example, *flags) -> tuple:
    """The benchmark on a folder holding one bundled example: (run, rows written)."""
    parts = tmp_path / "parts"
    parts.mkdir()
    shutil.copy(REPO / "resources" / "examples" / example, parts / example)
    rows = tmp_path / "rows.jsonl"
    run = run_folder(parts, "--rows", rows, *flags)
    assert run.returncode == 0, run.stderr
    return run, [json.loads(line) for line in rows.read_text().splitlines()]


def test_an_empty_folder_is_refused(tmp_path):
    run = run_folder(tmp_path)
    assert run.returncode == 2 and "no part files" in run.stderr


def test_gmsh_alg_11_is_measured_beside_ours_on_each_row(tmp_path):
    run, written = run_on_one_part(tmp_path, "l_shape.json", "--gmsh")
    assert len(written) == 2
    for row in written:
        peer = row["gmsh"]
        # gmsh's quads are its own (alg. 11 splits each triangle in three): more of them,
        # and the L's re-entrant corner is no irregular vertex of ours
        assert peer["quads"] > row["quads"] > 0
        assert 0.0 < peer["min_scaled_jacobian"] <= 1.0 and peer["mesh_s"] > 0.0
        assert row["irregular_vertices"] <= peer["irregular_vertices"]
    assert "of the 1 gmsh alg. 11 meshed too: minSJ >= gmsh's" in run.stdout


def test_each_face_is_checked_in_every_pose(tmp_path):
    # The corpus and family tests turn shapes the project drew or cut; a user's own folder
    # (the held-out faces) is checked the same way by the benchmark.
    run, written = run_on_one_part(tmp_path, "plate_hole.json", "--poses")
    assert len(written) == 2
    for row in written:
        assert row["same_in_poses"] is True and row["poses_differing"] == []
    assert "default: the same in every pose 1/1" in run.stdout
    assert "poses: same" in run.stdout
