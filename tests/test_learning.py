"""Families, augmentation, data sets, the network, training, ONNX parity and evaluation:
a tiny end-to-end run (a few samples, one epoch) — CI never trains a full model."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
import torch
from conftest import run_cli

from quadcnn_wb.core.field.reference import numerical_reference
from quadcnn_wb.core.layout.partition import build_partition
from quadcnn_wb.infer.encoding import canonical_angle, encode, swap_labels
from quadcnn_wb.infer.predictor import ModelError, Predictor
from quadcnn_wb.learn.dataset import generate, load_dataset, make_sample, save_dataset
from quadcnn_wb.learn.families import FAMILIES
from quadcnn_wb.learn.model import QuadCNN, knn
from quadcnn_wb.learn.train import RECIPES, export_onnx, ridge_targets, train


@pytest.mark.parametrize("name", sorted(FAMILIES))
def test_family_members_keep_the_topology_and_singular_points(name):
    fam = FAMILIES[name]
    rng = np.random.default_rng(11)
    for _ in range(3):
        params, domain = fam.sample(rng)
        assert set(params) == set(fam.ranges)
        ref = numerical_reference(domain, nodes=1200, labels=False)
        counts = ref.field.valences()
        assert (counts[3], counts[5]) == fam.singularities
        if name not in ("four_hole", "plate_hole"):  # the data set drops the few that fail
            build_partition(domain, ref.streamlines, ref.mesh.element_size)


def test_samples_are_deterministic_and_normalised():
    a, reason = make_sample("l_shape", seed=5, index=3, nodes=800)
    b, _ = make_sample("l_shape", seed=5, index=3, nodes=800)
    assert reason is None
    assert np.array_equal(a.x, b.x) and np.array_equal(a.y, b.y)
    other, _ = make_sample("l_shape", seed=5, index=4, nodes=800)
    assert not np.array_equal(a.x[:50], other.x[:50])
    radius = np.hypot(a.x[:, 0], a.x[:, 1])
    assert 0.3 < radius.max() <= 0.5 + 1e-6  # inside the unit-diagonal box's circle
    assert np.allclose(np.hypot(a.x[:, 2], a.x[:, 3]), 1.0, atol=1e-6)
    assert a.x.shape[1] == 10 and np.all((a.x[:, 4:] >= 0) & (a.x[:, 4:] <= 1))
    assert set(np.unique(a.x[:, 8:])) <= {0.0, 1.0}  # the rays' own labels
    angle = np.arctan2(a.x[:, 3], a.x[:, 2])
    assert np.all(angle > -np.pi / 4 - 1e-6) and np.all(angle <= np.pi / 4 + 1e-6)
    assert 0 < a.y.mean() < 0.2 and set(np.unique(a.y)) == {0, 1}


def _same_up_to_centre_and_scale(a, b):
    da, db = a[:, :2] - a[:, :2].mean(axis=0), b[:, :2] - b[:, :2].mean(axis=0)
    scale = np.linalg.norm(da) / np.linalg.norm(db)
    return np.allclose(db * scale, da, atol=1e-5) and np.allclose(a[:, 2:], b[:, 2:],
                                                                  atol=1e-5)


def test_encoding_carries_the_hints_of_v1_and_v2_with_their_labels():
    rng = np.random.default_rng(2)
    nodes = rng.uniform(size=(60, 2)) * [0.5, 1.0]  # tall: the settled pose is a quarter turn
    theta = rng.uniform(-0.7, 0.7, size=60)
    labels = rng.integers(0, 2, size=(60, 2))
    ray_labels = rng.integers(0, 2, size=(60, 2))
    hints = np.column_stack([labels, rng.random((60, 2)), ray_labels]).astype(float)
    x, swapped = encode(nodes, theta, hints)
    assert x.shape == (60, 10) and swapped.any()
    assert np.array_equal(x[:, 4:6], swap_labels(labels, swapped))  # paired as labels are
    assert np.allclose(x[:, 6:8], hints[:, 2:4], atol=1e-6)  # per-node values stay
    assert np.array_equal(x[:, 8:10], swap_labels(ray_labels, swapped))
    assert np.allclose(x[:, :4], encode(nodes, theta)[0])
    older, _ = encode(nodes, theta, hints[:, :4])  # 8-column data: only one pair
    assert np.array_equal(older, x[:, :8])


def test_encoding_ignores_placement_scale_rotation_and_mirror():
    rng = np.random.default_rng(0)
    nodes = rng.uniform(size=(50, 2)) * [1.0, 0.6]
    theta = 0.3 + rng.normal(scale=0.1, size=50)
    base, swapped = encode(nodes, theta)
    assert swapped.all() or not swapped.any()  # a pose change trades every node's labels
    moved, _ = encode(nodes * 1e4 + 7, theta)
    assert np.allclose(base, moved, atol=1e-5)
    # Turned and mirrored copies (the crosses move with them) settle in the same pose, up
    # to the bounding-box centre and diagonal, which are not turn-invariant.
    for a in (0.5, 2.0, -2.9):
        rot = nodes @ np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]])
        turned, turned_swapped = encode(rot, theta + a)
        assert _same_up_to_centre_and_scale(base, turned)
        # Labels follow their arm: the arm that was v1 is v1 again or traded everywhere.
        arm = canonical_angle(theta + a) - a - canonical_angle(theta)
        other_arm = np.abs((arm + np.pi / 2) % np.pi - np.pi / 2) > np.pi / 4
        assert np.array_equal(turned_swapped ^ other_arm, swapped)
    mirrored, _ = encode(nodes * [-1.0, 1.0], np.pi - theta)
    assert _same_up_to_centre_and_scale(base, mirrored)
    # Each of the 8 poses is undone: the settled moments are all non-negative.
    centred = base[:, :2] - base[:, :2].mean(axis=0)
    assert (centred[:, 0] ** 2).sum() >= (centred[:, 1] ** 2).sum()
    assert ((centred ** 3).sum(axis=0) >= 0).all()
    assert np.allclose(canonical_angle(theta + np.pi / 2), canonical_angle(theta), atol=1e-9)
    labels = rng.integers(0, 2, size=(50, 2))
    mask = rng.random(50) < 0.5
    assert np.array_equal(swap_labels(swap_labels(labels, mask), mask), labels)


def test_network_shapes_and_parameter_count():
    net = QuadCNN().eval()
    assert 380_000 < sum(p.numel() for p in net.parameters()) < 460_000
    for n in (37, 500):
        out = net(torch.rand(2, n, 4))
        assert out.shape == (2, n, 2)
    pos = torch.rand(1, 30, 2)
    idx = knn(pos, 10)
    brute = torch.argsort(((pos[0, :, None] - pos[0, None]) ** 2).sum(-1), dim=1)[:, :10]
    assert torch.equal(torch.sort(idx[0], dim=1).values, torch.sort(brute, dim=1).values)


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    """A 6-sample data set, a one-epoch model and its ONNX export."""
    folder = tmp_path_factory.mktemp("tiny")
    samples, dropped = generate("concave", 6, seed=3, nodes=600, workers=2, progress=False)
    assert len(samples) + sum(dropped.values()) == 6 and len(samples) >= 4
    data = folder / "data.npz"
    save_dataset(data, samples, {"family": "concave", "seed": 3})
    model = folder / "model.onnx"
    meta = train(data, model, epochs=1, seed=0, recipe="fast", threads=2, progress=False)
    return data, model, meta, samples


def test_training_goes_on_from_a_checkpoint(tiny, tmp_path):
    data, model, _, _ = tiny
    checkpoint = model.with_suffix(".ckpt.pt")
    assert checkpoint.is_file()
    meta = train(data, tmp_path / "more.onnx", epochs=1, seed=0, recipe="fast", threads=2,
                 progress=False, init=checkpoint)
    assert meta["recipe"]["init"] == checkpoint.name
    with pytest.raises(ValueError, match="another architecture"):
        train(data, tmp_path / "paper.onnx", epochs=1, recipe="paper", progress=False,
              init=checkpoint)
    (tmp_path / "junk.ckpt.pt").write_bytes(b"junk")
    with pytest.raises(ValueError, match="not a training checkpoint"):
        train(data, tmp_path / "junk.onnx", epochs=1, recipe="fast", progress=False,
              init=tmp_path / "junk.ckpt.pt")


def test_rays_recipe_reads_the_hints(tiny, tmp_path):
    data, _, _, samples = tiny
    model = tmp_path / "rays.onnx"
    meta = train(data, model, epochs=1, seed=0, recipe="rays", threads=2, progress=False)
    assert meta["input_shape"] == ["batch", "points", 10] and "rays:" in meta["input"]
    predictor = Predictor(model)
    assert predictor.inputs == 10
    assert predictor.probabilities(samples[0].x).shape == (len(samples[0].x), 2)
    with pytest.raises(ModelError, match="takes 10 input columns"):
        predictor.probabilities(samples[0].x[:, :8])
    old = tmp_path / "old.npz"  # a data set from before the hints: four columns
    save_dataset(old, [dataclasses.replace(s, x=s.x[:, :4]) for s in samples], {})
    with pytest.raises(ValueError, match="has 4 input columns, the model takes 10"):
        train(old, tmp_path / "no.onnx", epochs=1, recipe="rays", progress=False)


def test_data_set_round_trip(tiny):
    data, _, _, samples = tiny
    back, meta = load_dataset(data)
    assert meta["family"] == "concave" and meta["samples"] == len(samples)
    for a, b in zip(samples, back):
        assert np.array_equal(a.x, b.x) and np.array_equal(a.y, b.y)


def test_training_writes_model_and_metadata(tiny):
    _, model, meta, _ = tiny
    disk = json.loads(model.with_suffix(".json").read_text())
    assert disk["sha256"] == meta["sha256"]
    import hashlib

    assert hashlib.sha256(model.read_bytes()).hexdigest() == meta["sha256"]
    for key in ("family", "input", "threshold", "recipe", "data", "metrics_test_split",
                "versions"):
        assert key in disk
    assert set(disk["metrics_test_split"]) == {"accuracy", "iou", "miou", "precision",
                                                "recall", "zero_baseline_accuracy", "samples"}


@pytest.mark.parametrize("architecture", [{}, RECIPES["fast"]["model"],
                                          RECIPES["rays"]["model"]],
                         ids=["table1", "fast", "rays"])
def test_onnx_matches_torch(tiny, tmp_path, architecture):
    _, _, _, samples = tiny
    torch.manual_seed(1)
    net = QuadCNN(**architecture).eval()
    path = tmp_path / "parity.onnx"
    export_onnx(net, path)
    predictor = Predictor(path, threads=1)
    agree = total = 0
    for sample in samples:
        with torch.no_grad():
            x = torch.from_numpy(np.ascontiguousarray(sample.x[None, :, :net.inputs]))
            ref = torch.sigmoid(net(x))[0].numpy()
        got = predictor.probabilities(sample.x)  # reads the columns it takes
        assert np.allclose(got, ref, atol=1e-4)
        agree += int(np.sum((got >= 0.5) == (ref >= 0.5)))
        total += ref.size
    assert agree / total >= 0.999


def test_ridge_targets_keep_the_labels_and_fall_off_with_distance(tiny):
    _, _, _, samples = tiny
    sample = samples[0]
    target = ridge_targets(sample)
    assert np.array_equal(target >= 0.5, sample.y > 0)
    for c in range(2):
        on = sample.y[:, c] > 0
        off = ~on
        distance = np.min(np.linalg.norm(sample.x[off, None, :2] - sample.x[None, on, :2],
                                         axis=-1), axis=1)
        order = np.argsort(distance)
        assert np.all(np.diff(target[off, c][order]) <= 1e-7)  # farther, never higher
        assert target[off, c][order[0]] > 0.2 and target[off, c][order[-1]] < 1e-3


def test_evaluate_command(tiny, tmp_path):
    data, model, _, _ = tiny
    out = tmp_path / "metrics.json"
    result = run_cli("evaluate", model, data, "-o", out)
    assert result.returncode == 0, result.stderr
    metrics = json.loads(out.read_text())
    assert metrics["samples"] >= 4
    assert 0.0 <= metrics["iou"] <= 1.0 and metrics["zero_baseline_accuracy"] > 0.8


def test_bad_models_and_data_are_refused(tmp_path):
    corrupt = tmp_path / "corrupt.onnx"
    corrupt.write_bytes(b"not a model")
    with pytest.raises(ModelError, match="not a readable ONNX model"):
        Predictor(corrupt)
    with pytest.raises(ModelError, match="no such model file"):
        Predictor(tmp_path / "missing.onnx")
    bad = tmp_path / "bad.npz"
    bad.write_bytes(b"zzz")
    result = run_cli("evaluate", corrupt, bad)
    assert result.returncode == 2 and result.stderr.startswith("error:")
    with pytest.raises(ValueError, match="not a QuadCNN data set"):
        load_dataset(bad)


def test_families_and_dataset_commands(tmp_path):
    listing = run_cli("families")
    assert listing.returncode == 0
    for name in FAMILIES:
        assert listing.stdout.count(f"{name}:") == 1
    out = tmp_path / "d.npz"
    result = run_cli("dataset", "semicircle", "-n", "3", "--seed", "2", "--nodes", "500",
                     "--workers", "1", "-o", out)
    assert result.returncode == 0, result.stderr
    assert "samples written" in result.stdout
    assert load_dataset(out)[1]["samples"] >= 2
    bad = run_cli("dataset", "hexagonal", "-o", out)
    assert bad.returncode == 2 and "unknown family" in bad.stderr


def test_topology_signatures_ignore_rotation_mirroring_and_order():
    from quadcnn_wb.core.input.domain import domain_from_json
    from quadcnn_wb.core.input.transform import similarity, transform_domain_json
    from quadcnn_wb.infer.signature import topology_signature

    rng = np.random.default_rng(4)
    seen = {}
    for name, fam in FAMILIES.items():
        _, domain = fam.sample(rng)
        moved = domain_from_json(transform_domain_json(domain.to_json(),
                                                       similarity(33, 2.0, mirror=True)))
        assert topology_signature(moved) == topology_signature(domain) == fam.topology
        seen[fam.topology] = name
    assert len(seen) == len(FAMILIES)  # every family has its own signature
