"""`python -m quadcnn_wb background`: the DESIGN.md contract, pictures, and exit status 2."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import REPO, SHARED_EXAMPLES, run_cli

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def test_background_json_and_png(tmp_path):
    out, png = tmp_path / "bg.json", tmp_path / "bg.png"
    result = run_cli("background", SHARED_EXAMPLES / "plate_hole.json", "--nodes", "1500",
                     "-o", out, "--png", png)
    assert result.returncode == 0, result.stderr
    data = json.loads(out.read_text())
    assert set(data) == {"nodes", "triangles", "boundary_nodes", "corners", "healed"}
    assert data["healed"] == []
    nodes, tris = np.array(data["nodes"]), np.array(data["triangles"])
    assert nodes.shape[1] == 2 and abs(len(nodes) - 1500) <= 75
    assert tris.min() == 0 and tris.max() == len(nodes) - 1
    a, b, c = (nodes[tris[:, k]] for k in range(3))
    cross = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
    assert np.all(cross > 0)
    assert [round(c["angle_deg"], 6) for c in data["corners"]] == [90.0] * 4
    assert all(0 <= c["node"] < len(nodes) for c in data["corners"])
    assert png.read_bytes()[:8] == PNG_MAGIC and png.stat().st_size > 20_000
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temp files


def test_step_input_on_the_command_line(tmp_path):
    from test_cad_import import plate_with_hole, write_cad

    step = write_cad(tmp_path / "plate.step", plate_with_hole)
    result = run_cli("background", step, "-o", tmp_path / "bg.json")
    assert result.returncode == 0, result.stderr
    assert len(json.loads((tmp_path / "bg.json").read_text())["corners"]) == 4


@pytest.mark.parametrize("args, message", [
    (["background", "missing.json"], "missing.json: no such file"),
    (["background", "open.json"], "loop 0: open loop"),
    (["background", "open.json", "--nodes", "many"], "--nodes: expected a whole number"),
    (["background", "open.json", "--nodes", "3"], "--nodes: expected at least 8"),
    (["background", "good.json", "-o", "result.txt"], "output must end in .json"),
    (["background", "good.json", "-o", "no/such/dir/x.json"], "does not exist"),
    (["frobnicate"], "invalid choice"),
])
def test_bad_requests_exit_2_with_one_error_line(tmp_path, args, message):
    (tmp_path / "open.json").write_text(json.dumps(
        {"loops": [[{"line": [[0, 0], [1, 0]]}, {"line": [[1, 0], [1, 1]]}]]}))
    (tmp_path / "good.json").write_text((SHARED_EXAMPLES / "l_shape.json").read_text())
    result = run_cli(*args, cwd=tmp_path)
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), result.stderr
    assert message in lines[0]
    assert "Traceback" not in result.stderr


def test_failed_run_keeps_the_earlier_result(tmp_path):
    out = tmp_path / "bg.json"
    assert run_cli("background", SHARED_EXAMPLES / "l_shape.json", "-o", out).returncode == 0
    before = out.read_bytes()
    bad = tmp_path / "bad.json"
    bad.write_text('{"loops": [[{"circle": {"center": [0, 0], "radius": -1}}]]}')
    result = run_cli("background", bad, "-o", out, "--png", tmp_path / "pic.png")
    assert result.returncode == 2
    assert out.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.json", "bg.json"]


def test_installed_console_script_exists():
    import shutil
    import sys
    from pathlib import Path

    script = Path(sys.executable).parent / "quadcnn"
    assert script.exists() or shutil.which("quadcnn"), "pip install -e . should add `quadcnn`"
    assert (REPO / "quadcnn_wb" / "__main__.py").is_file()
