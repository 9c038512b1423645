"""Training for one design in a separate process, as the FreeCAD TrainModel command runs it:
progress lines the GUI can show, a model with metadata naming the design and its topology,
and clear refusals."""

from __future__ import annotations

import json
import subprocess
import sys

from conftest import REPO

from quadcnn_wb.core.input.transform import similarity, transform_domain_json
from quadcnn_wb.infer.predictor import Predictor
from quadcnn_wb.learn.families import family


def run_design_train(*args):
    return subprocess.run([sys.executable, "-m", "quadcnn_wb.learn.design_train", *map(str, args)],
                          capture_output=True, text=True, cwd=REPO, timeout=600)


def test_design_variants_train_a_model_with_progress(tmp_path):
    import numpy as np

    rng = np.random.default_rng(0)
    design = family("l_shape").sample(rng)[1].to_json()
    variants = [design] + [transform_domain_json(design, similarity(0, scale=s))
                           for s in (0.9, 1.1, 1.2)]
    spec = tmp_path / "variants.json"
    spec.write_text(json.dumps({"name": "bracket", "domains": variants}))
    model = tmp_path / "bracket.onnx"
    result = run_design_train(spec, "-o", model, "--samples", "12", "--epochs", "1",
                              "--workers", "2")
    assert result.returncode == 0, result.stderr[-2000:]
    fractions = [float(line.split()[1]) for line in result.stdout.splitlines()
                 if line.startswith("progress ")]
    assert len(fractions) > 3 and fractions == sorted(fractions) and fractions[-1] > 0.99
    assert result.stdout.strip().splitlines()[-1] == f"model {model}"
    meta = Predictor(model).metadata
    assert meta["design"] == "bracket" and meta["family"] == "design:bracket"
    assert meta["topology"] == family("l_shape").topology
    assert not model.with_suffix(".npz").exists()  # the intermediate data set is removed


def test_design_train_refuses_an_empty_variant_list(tmp_path):
    spec = tmp_path / "variants.json"
    spec.write_text(json.dumps({"name": "none", "domains": []}))
    result = run_design_train(spec, "-o", tmp_path / "m.onnx")
    assert result.returncode == 2
    assert result.stderr.startswith("error:") and "no design variants" in result.stderr
    assert not (tmp_path / "m.onnx").exists()
