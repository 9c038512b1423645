"""The cnn meshing path wired end to end with a real ONNX model and onnxruntime: an
untrained network predicts nothing useful, so every separatrix falls back to numerical
tracing — and the mesh is still valid; a model of another topology is refused."""

from __future__ import annotations

import json

import numpy as np
import pytest
import torch
from conftest import SHARED_EXAMPLES, run_cli

from quadcnn_wb.bench.meshcheck import check_quad_mesh
from quadcnn_wb.core.input.load import load_domain
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


def test_auto_picks_a_user_model_of_the_same_topology(untrained, tmp_path, monkeypatch):
    from quadcnn_wb.infer.models import available_models, model_for

    folder = tmp_path / "models"
    folder.mkdir()
    domain = load_domain(SHARED_EXAMPLES / "l_shape.json")
    model = untrained(topology_signature(domain))
    meta = json.loads(model.with_suffix(".json").read_text())
    for name, iou in (("mine", 0.9), ("weak", 0.3)):
        (folder / f"{name}.onnx").write_bytes(model.read_bytes())
        (folder / f"{name}.json").write_text(json.dumps(
            {**meta, "metrics_test_split": {"iou": iou}}))
    (folder / "broken.onnx").write_bytes(b"not a model")
    (folder / "broken.json").write_text("{ not json")
    monkeypatch.setenv("QUADCNN_MODELS", str(folder))
    from quadcnn_wb.infer.models import AUTO_MIN_IOU

    entry = model_for(domain, min_iou=AUTO_MIN_IOU)
    assert entry is not None and entry.origin == "user" and entry.path.name == "mine.onnx"
    (folder / "mine.json").unlink()  # now only the weak one: cnn takes it, auto does not
    assert model_for(domain).path.name == "weak.onnx"
    assert model_for(domain, min_iou=AUTO_MIN_IOU) is None
    result = run_cli("mesh", SHARED_EXAMPLES / "l_shape.json", "-o", tmp_path / "weak.json")
    assert json.loads((tmp_path / "weak.json").read_text())["method"] == "numerical"
    (folder / "mine.json").write_text(json.dumps({**meta, "metrics_test_split": {"iou": 0.9}}))
    assert all(e.path.name != "broken.onnx" for e in available_models())
    assert model_for(load_domain(SHARED_EXAMPLES / "plate_hole.json")) is None or \
        model_for(load_domain(SHARED_EXAMPLES / "plate_hole.json")).origin == "shipped"
    out = tmp_path / "auto.json"
    result = run_cli("mesh", SHARED_EXAMPLES / "l_shape.json", "-o", out)
    assert result.returncode == 0, result.stderr
    assert json.loads(out.read_text())["method"] == "cnn"
    result = run_cli("mesh", SHARED_EXAMPLES / "l_shape.json", "--method", "numerical",
                     "-o", out)
    assert result.returncode == 0 and json.loads(out.read_text())["method"] == "numerical"


def test_cnn_without_a_matching_model_is_refused(tmp_path, monkeypatch):
    monkeypatch.setenv("QUADCNN_MODELS", str(tmp_path))  # empty user folder
    domain = load_domain(SHARED_EXAMPLES / "l_shape.json")
    from quadcnn_wb.infer.models import model_for

    if model_for(domain) is not None:
        pytest.fail("a shipped model for the l_shape topology: pick another shape here")
    result = run_cli("mesh", SHARED_EXAMPLES / "l_shape.json", "--method", "cnn",
                     "-o", tmp_path / "m.json")
    assert result.returncode == 2
    assert result.stderr.startswith("error:") and "no model for this domain" in \
        result.stderr and str(tmp_path) in result.stderr
    assert not (tmp_path / "m.json").exists()
