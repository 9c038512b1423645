"""The models shipped in resources/models: complete metadata, the file it describes (sha256),
the topology of its family, and labels that still match the numerical reference on a
handful of fresh samples (a seed never used for training data)."""

from __future__ import annotations

import hashlib

import pytest

from quadcnn_wb.infer.metrics import Confusion
from quadcnn_wb.infer.models import SHIPPED_MODELS, available_models
from quadcnn_wb.infer.predictor import INPUT_WIDTHS, Predictor
from quadcnn_wb.learn.dataset import make_sample
from quadcnn_wb.learn.families import family

REQUIRED = ("semicircle", "concave", "four_hole")
FRESH_SEED = 424242  # training data uses small seeds (see docs/learning.md)


def shipped():
    return {e.family: e for e in available_models([(SHIPPED_MODELS, "shipped")])}


def test_the_required_families_ship_a_model():
    assert set(REQUIRED) <= set(shipped())


@pytest.mark.parametrize("name", REQUIRED)
def test_metadata_is_complete_and_matches_the_file(name):
    entry = shipped()[name]
    meta = Predictor(entry.path).metadata
    for key in ("family", "topology", "input", "threshold", "recipe", "data",
                "metrics_test_split", "sha256", "versions"):
        assert key in meta, key
    assert meta["sha256"] == hashlib.sha256(entry.path.read_bytes()).hexdigest()
    assert meta["topology"] == family(name).topology
    assert meta["data"]["seed"] is not None and meta["data"]["seed"] != FRESH_SEED
    assert 0.0 < meta["threshold"] < 1.0
    assert meta["input_shape"] == ["batch", "points", Predictor(entry.path).inputs]
    assert meta["input_shape"][2] in INPUT_WIDTHS


@pytest.mark.parametrize("name", REQUIRED)
def test_labels_match_the_reference_on_fresh_samples(name):
    """What the metadata promises holds on samples the model never saw (with the margin
    a handful of samples needs): the shipped file, the encoding and the threshold agree."""
    predictor = Predictor(shipped()[name].path, threads=2)
    promised = predictor.metadata["metrics_test_split"]
    confusion, count = Confusion(), 0
    for index in range(4):
        sample, _ = make_sample(name, FRESH_SEED, index)
        if sample is None:
            continue
        confusion.add(predictor.labels(sample.x), sample.y)
        count += 1
    assert count >= 3
    metrics = confusion.metrics(count)
    assert metrics["accuracy"] >= promised["accuracy"] - 0.03, (metrics, promised)
    assert metrics["iou"] >= promised["iou"] - 0.15, (metrics, promised)
    assert metrics["iou"] > 0.3  # far from the all-zeros answer
