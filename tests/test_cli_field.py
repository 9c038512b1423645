"""`python -m quadcnn_wb field`: the DESIGN.md 'field' JSON, its picture, bad input."""

from __future__ import annotations

import json

import numpy as np
from conftest import SHARED_EXAMPLES, run_cli
from test_cli_background import PNG_MAGIC


def test_field_json_contract_and_picture(tmp_path):
    out, png = tmp_path / "field.json", tmp_path / "field.png"
    result = run_cli("field", SHARED_EXAMPLES / "semicircle.json", "-o", out, "--png", png)
    assert result.returncode == 0, result.stderr
    assert "2 valence-3 and 0 valence-5" in result.stdout
    data = json.loads(out.read_text())
    for key in ("nodes", "triangles", "boundary_nodes", "corners", "frames", "singularities",
                "streamlines", "labels"):
        assert key in data, key
    n = len(data["nodes"])
    frames, labels = np.array(data["frames"]), np.array(data["labels"])
    assert frames.shape == (n, 4) and labels.shape == (n, 2)
    assert np.allclose(frames[:, 0] * frames[:, 2] + frames[:, 1] * frames[:, 3], 0)
    assert set(np.unique(labels)) == {0, 1}
    assert sorted(s["valence"] for s in data["singularities"]) == [3, 3]
    assert all(len(s["xy"]) == 2 for s in data["singularities"])
    assert len(data["streamlines"]) == 5
    assert all(len(line) >= 2 and len(line[0]) == 2 for line in data["streamlines"])
    assert png.read_bytes()[:8] == PNG_MAGIC


def test_field_bad_input_exits_2(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"loops": [[{"line": [[0, 0], [1, 0]]}, {"spline": []}]]}')
    result = run_cli("field", bad, "-o", tmp_path / "f.json")
    assert result.returncode == 2
    assert result.stderr.strip() == ("error: loop 0, segment 1: unknown segment kind 'spline' "
                                     "(expected line, arc or circle)")
    assert not (tmp_path / "f.json").exists()
