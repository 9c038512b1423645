"""Shared fixtures: the reference examples in ../shared and small domain builders."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SHARED_EXAMPLES = REPO.parent / "shared" / "examples"
EXAMPLE_NAMES = ["concave", "four_hole", "l_shape", "plate_hole", "semicircle"]


def rect(w, h, x0=0.0, y0=0.0):
    """Loop of four lines, counter-clockwise."""
    p = [[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0 + h]]
    return [{"line": [p[i], p[(i + 1) % 4]]} for i in range(4)]


def circle(cx, cy, r):
    return [{"circle": {"center": [cx, cy], "radius": r}}]


@pytest.fixture(params=EXAMPLE_NAMES)
def example_path(request) -> Path:
    path = SHARED_EXAMPLES / f"{request.param}.json"
    assert path.is_file(), f"missing shared example {path}"
    return path


@pytest.fixture
def write_json(tmp_path):
    def write(data, name="domain.json"):
        path = tmp_path / name
        path.write_text(json.dumps(data) if not isinstance(data, str) else data)
        return path

    return write


def run_cli(*args, cwd=None):
    """The real command line in a fresh interpreter."""
    return subprocess.run([sys.executable, "-m", "quadcnn_wb", *map(str, args)],
                          capture_output=True, text=True, cwd=cwd, timeout=300)
