"""The cnn meshing path wired end to end with a real ONNX model and onnxruntime: an
untrained network predicts nothing useful, so every separatrix falls back to numerical
tracing — and the mesh is still valid; a model of another topology is refused."""

from __future__ import annotations

import json

import numpy as np
import pytest
import torch
from conftest import SHARED_EXAMPLES, run_cli
from meshcheck import check_quad_mesh

from quadcnn_wb.core.domain import load_domain
from quadcnn_wb.core.pipeline import mesh_domain
from quadcnn_wb.infer.cnn import cnn_streamlines
from quadcnn_wb.infer.predictor import ModelError
from quadcnn_wb.infer.signature import topology_signature
from quadcnn_wb.learn.model import QuadCNN
from quadcnn_wb.learn.train import export_onnx


@pytest.fixture(scope="module")
def untrained(tmp_path_factory):
    def make(topology):
        folder = tmp_path_factory.mktemp("model")
        path = folder / "untrained.onnx"
        torch.manual_seed(0)
        export_onnx(QuadCNN(), path)
        path.with_suffix(".json").write_text(json.dumps({"family": "test",
                                                          "topology": topology}))
        return path
    return make


def test_cnn_path_falls_back_and_still_meshes(untrained):
    domain = load_domain(SHARED_EXAMPLES / "plate_hole.json")
    model = untrained(topology_signature(domain))
    result = mesh_domain(domain, method="cnn", learned_streamlines=cnn_streamlines(model))
    assert result.method == "cnn"
    assert result.fallback == list(range(len(result.streamlines) - len(result.cuts)))
    mesh = result.mesh
    check_quad_mesh(mesh.nodes, mesh.quads, domain.area, lambda p: True)
    assert result.quality["irregular_vertices"] == 4
    assert "reconstruction" in result.timings


def test_model_of_another_topology_is_refused(untrained, tmp_path):
    model = untrained("1:11111133")  # the concave family
    domain = load_domain(SHARED_EXAMPLES / "plate_hole.json")
    with pytest.raises(ModelError, match="trained for topology 1:11111133"):
        mesh_domain(domain, method="cnn", learned_streamlines=cnn_streamlines(model))
    result = run_cli("mesh", SHARED_EXAMPLES / "plate_hole.json", "--model", model,
                     "-o", tmp_path / "m.json")
    assert result.returncode == 2 and "trained for topology" in result.stderr
    assert not (tmp_path / "m.json").exists()


def test_mesh_command_with_a_model_reports_the_method(untrained, tmp_path):
    domain = load_domain(SHARED_EXAMPLES / "l_shape.json")
    model = untrained(topology_signature(domain))
    out = tmp_path / "m.json"
    result = run_cli("mesh", SHARED_EXAMPLES / "l_shape.json", "--method", "cnn", "--model",
                     model, "-o", out)
    assert result.returncode == 0, result.stderr
    data = json.loads(out.read_text())
    assert data["method"] == "cnn"
    assert isinstance(data["fallback"], list)
    assert np.array(data["quads"]).shape[1] == 4
