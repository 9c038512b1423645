"""Training, validation and ONNX export: `quadcnn train DATA -o MODEL.onnx`.

Recipes:
- "paper" (default, §3.2): loss 0.5 * cross-entropy + 0.5 * dice on the sigmoid outputs,
  SGD with learning rate 1e-3 and momentum 0.9, batch 4, the Table 1 network.
- "fast": the same loss with the cross-entropy weighted 4:1 towards the rare label 1,
  AdamW (1e-3, one-cycle schedule), and a lighter network (global feature 256, head
  128-128-64, dropout 0.1, Fourier features of the positions): a third of the cost per
  step, so three times the steps in a CPU session, which is what decides here.
- "rays": the fast recipe's optimiser on a smaller network that also reads the six ray
  hints (infer.rays: where coarse field-following rays from the singular points run, and
  the labels' rule applied to them).  The hints place the bands; the network learns
  where they are off (rays that drift, end early or late).  No ridge targets: the hints
  already tell every point which way the band lies.  (Models of the first rays recipe
  read only the four distance hints: 8 columns.)
80/20 split by the seed; the model with the best validation IoU is kept (early stop after
`patience` epochs without improvement), checkpointed every epoch, exported to ONNX (opset
17, dynamic batch and point count) with a metadata JSON beside it.
"""

from __future__ import annotations

import dataclasses
import hashlib
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import torch

from ..core.atomic import write_atomic, write_json_atomic
from ..infer.encoding import ENCODING
from ..infer.metrics import Confusion
from ..infer.rays import RAY_ENCODING
from .dataset import load_dataset
from .model import QuadCNN, knn

RECIPES = {
    "paper": {"optimizer": "sgd", "lr": 1e-3, "momentum": 0.9, "batch": 4, "pos_weight": 1.0,
              "schedule": "constant"},
    "fast": {"optimizer": "adamw", "lr": 2e-3, "batch": 4, "pos_weight": "auto",
             "schedule": "onecycle", "weight_decay": 1e-4, "ridge": True,
             "model": {"dropout": 0.1, "octaves": 4, "global_width": 256,
                       "head": [128, 128, 64], "keypoints": 32}},
    "rays": {"optimizer": "adamw", "lr": 2e-3, "batch": 4, "pos_weight": "auto",
             "schedule": "onecycle", "weight_decay": 1e-4, "ridge": False,
             "model": {"inputs": 10, "dropout": 0.1, "octaves": 2, "global_width": 128,
                       "head": [64, 64, 32]}},
}


def loss_fn(logits: torch.Tensor, target: torch.Tensor, pos_weight: float) -> torch.Tensor:
    """0.5 * (weighted) binary cross-entropy + 0.5 * dice, as the paper's §3.2."""
    bce = torch.nn.functional.binary_cross_entropy_with_logits(
        logits, target, pos_weight=torch.tensor(pos_weight))
    z = torch.sigmoid(logits)
    dice = 1 - 2 * ((z * target).sum() + 1e-5) / ((z * z).sum() + (target * target).sum()
                                                  + 1e-5)
    return 0.5 * bce + 0.5 * dice


def ridge_targets(sample, tail: float = 0.45, width: float = 2.0) -> np.ndarray:
    """(N, 2) training targets: 1 on the label-1 band, a ridge below 0.5 around it.

    A thin band of ones in a sea of zeros tells a network that puts the band three
    elements off nothing about which way to move it; a tail that decays with the distance
    to the band (`width` element sizes, the element size being the median neighbour
    distance) gives every point that direction, while staying under the 0.5 threshold so
    the labels themselves are unchanged.
    """
    from scipy.spatial import cKDTree

    tree = cKDTree(sample.x[:, :2])
    spacing = float(np.median(tree.query(sample.x[:, :2], k=2)[0][:, 1]))
    out = sample.y.astype(np.float32)
    for c in range(2):
        on = sample.y[:, c] > 0
        if not on.any():
            continue
        distance = cKDTree(sample.x[on, :2]).query(sample.x[:, :2])[0]
        ridge = tail * np.exp(-(distance / (width * spacing)) ** 2)
        out[:, c] = np.where(on, 1.0, ridge)
    return out


def input_columns(samples, width: int, data_path) -> list:
    """The samples with the first `width` input columns (a data set holds the paper's four
    and the ray hints; a model takes what it was built for)."""
    have = samples[0].x.shape[1] if samples else width
    if have < width:
        raise ValueError(f"{data_path}: has {have} input columns, the model takes {width} "
                         "(regenerate it with 'quadcnn dataset')")
    if have == width:
        return samples
    return [dataclasses.replace(s, x=np.ascontiguousarray(s.x[:, :width])) for s in samples]


def split(n: int, seed: int, fraction: float = 0.2):
    order = np.random.default_rng(seed).permutation(n)
    n_val = max(1, int(round(fraction * n))) if n > 1 else 0
    return np.sort(order[n_val:]), np.sort(order[:n_val])


def _batches(samples, indices, batch: int, rng, targets=None):
    order = rng.permutation(indices)
    for start in range(0, len(order), batch):
        chosen = [samples[i] for i in order[start:start + batch]]
        n = min(len(s.x) for s in chosen)  # crop to a common point count
        picks = [np.sort(rng.choice(len(s.x), n, replace=False)) if len(s.x) > n
                 else np.arange(n) for s in chosen]
        x = np.stack([s.x[p] for s, p in zip(chosen, picks)])
        if targets is None:
            y = np.stack([s.y[p] for s, p in zip(chosen, picks)]).astype(np.float32)
        else:
            chosen_targets = [targets[i] for i in order[start:start + batch]]
            y = np.stack([t[p] for t, p in zip(chosen_targets, picks)])
        yield torch.from_numpy(x), torch.from_numpy(y)


def predict_torch(net, samples, indices) -> list:
    net.eval()
    with torch.no_grad():
        return [torch.sigmoid(net(torch.from_numpy(samples[i].x[None])))[0].numpy()
                for i in indices]


def metrics_at(probabilities, samples, indices, threshold: float) -> dict:
    confusion = Confusion()
    for prob, i in zip(probabilities, indices):
        confusion.add(prob >= threshold, samples[i].y)
    return confusion.metrics(len(indices))


def evaluate_torch(net, samples, indices, threshold: float = 0.5) -> dict:
    return metrics_at(predict_torch(net, samples, indices), samples, indices, threshold)


def best_threshold(probabilities, samples, indices) -> float:
    """The decision threshold with the best IoU on the validation split.

    Dice and the class weighting shift the sigmoid's calibration; the threshold that
    turns probabilities into labels is part of the model (it is in the metadata).
    """
    candidates = np.round(np.arange(0.2, 0.81, 0.05), 2)
    scores = [metrics_at(probabilities, samples, indices, t)["iou"] for t in candidates]
    return float(candidates[int(np.argmax(scores))])


def train(data_path, out_path, epochs: int = 30, seed: int = 0, recipe: str = "paper",
          threads: int = 2, patience: int = 6, progress: bool = True,
          minutes: float | None = None, monitor: int = 100, report=None,
          meta_extra: dict | None = None, init=None) -> dict:
    """Train, keep the best epoch by validation IoU, export ONNX and its metadata.

    `minutes` bounds the wall time (the epoch under way stops, the best model so far is
    kept); `monitor` validation samples choose the best epoch, the whole validation split
    gives the reported metrics and the decision threshold.  `report(fraction, text)`, when
    given, hears about every step (the FreeCAD training dialog's progress bar).  `init`, a
    checkpoint (.ckpt.pt) of the same recipe, starts from its best weights: training can go
    on across sessions (with a fresh schedule).
    """
    if recipe not in RECIPES:
        raise ValueError(f"unknown recipe {recipe!r} (known: {', '.join(RECIPES)})")
    settings = RECIPES[recipe]
    samples, meta = load_dataset(data_path)
    if len(samples) < 2:
        raise ValueError(f"{data_path}: needs at least 2 samples, has {len(samples)}")
    architecture = settings.get("model", {})
    samples = input_columns(samples, architecture.get("inputs", 4), data_path)
    torch.manual_seed(seed)
    torch.set_num_threads(threads)
    torch.use_deterministic_algorithms(True, warn_only=True)
    rng = np.random.default_rng(seed)
    train_idx, val_idx = split(len(samples), seed)
    watch = val_idx[:monitor]
    pos_weight = settings["pos_weight"]
    if pos_weight == "auto":  # sqrt of the negative:positive ratio of the training labels
        ones = np.mean([samples[i].y.mean() for i in train_idx])
        pos_weight = float(np.sqrt((1 - ones) / max(ones, 1e-6)))
    targets = ({i: ridge_targets(samples[i]) for i in train_idx} if settings.get("ridge")
               else None)
    net = QuadCNN(**architecture)
    if init is not None:
        try:
            start = torch.load(init, map_location="cpu", weights_only=False)
        except FileNotFoundError:
            raise ValueError(f"{init}: no such checkpoint") from None
        except Exception as exc:
            raise ValueError(f"{init}: not a training checkpoint ({type(exc).__name__})") \
                from None
        if start.get("architecture", {}) != architecture:
            raise ValueError(f"{init}: a checkpoint of another architecture "
                             f"({start.get('architecture')}), not recipe {recipe!r}'s")
        net.load_state_dict(start["best_state"] or start["state"])
    if settings["optimizer"] == "sgd":
        opt = torch.optim.SGD(net.parameters(), lr=settings["lr"], momentum=settings["momentum"])
    else:
        opt = torch.optim.AdamW(net.parameters(), lr=settings["lr"],
                                weight_decay=settings["weight_decay"])
    steps_per_epoch = -(-len(train_idx) // settings["batch"])
    schedule = (torch.optim.lr_scheduler.OneCycleLR(opt, settings["lr"],
                                                    total_steps=epochs * steps_per_epoch,
                                                    pct_start=0.05)
                if settings["schedule"] == "onecycle" else None)
    out_path = Path(out_path)
    checkpoint = out_path.with_suffix(".ckpt.pt")
    best, best_state, best_epoch, history = -1.0, None, 0, []
    started = time.perf_counter()
    out_of_time = False
    for epoch in range(1, epochs + 1):
        net.train()
        losses = []
        for step, (x, y) in enumerate(_batches(samples, train_idx, settings["batch"], rng,
                                                    targets), 1):
            with torch.no_grad():
                idx = knn(x[..., :2], net.k)
            loss = loss_fn(net(x, idx), y, pos_weight)
            opt.zero_grad()
            loss.backward()
            opt.step()
            if schedule is not None:
                schedule.step()
            losses.append(float(loss.detach()))
            if report is not None:
                report(((epoch - 1) * steps_per_epoch + step) / (epochs * steps_per_epoch),
                       f"epoch {epoch}/{epochs}, loss {np.mean(losses):.3f}")
            if progress:
                sys.stderr.write(f"\repoch {epoch}/{epochs} step {step}/{steps_per_epoch} "
                                 f"loss {np.mean(losses):.4f} ")
                sys.stderr.flush()
            if minutes is not None and time.perf_counter() - started > 60 * minutes:
                out_of_time = True
                break
        val = evaluate_torch(net, samples, watch)
        history.append({"epoch": epoch, "loss": float(np.mean(losses)),
                        "seconds": time.perf_counter() - started, **val})
        if progress:
            sys.stderr.write(f"| val IoU {val['iou']:.3f} acc {val['accuracy']:.4f} "
                             f"({time.perf_counter() - started:.0f}s)\n")
        if val["iou"] > best:
            best, best_epoch = val["iou"], epoch
            best_state = {k: v.clone() for k, v in net.state_dict().items()}
        state = {"epoch": epoch, "state": net.state_dict(), "best_state": best_state,
                 "architecture": architecture}
        write_atomic(checkpoint, lambda tmp, state=state: torch.save(state, tmp))
        if epoch - best_epoch >= patience or out_of_time:
            break
    net.load_state_dict(best_state)
    probabilities = predict_torch(net, samples, val_idx)
    threshold = best_threshold(probabilities, samples, val_idx)
    val = metrics_at(probabilities, samples, val_idx, threshold)
    export_onnx(net, out_path)
    metadata = {
        "family": meta.get("family"), "topology": meta.get("topology"), **(meta_extra or {}),
        "input": ENCODING + ("; then " + RAY_ENCODING if net.inputs > 4 else ""),
        "input_shape": ["batch", "points", net.inputs],
        "output": "probabilities of label 1 for v1 and v2", "threshold": threshold,
        "architecture": {"k": net.k, **architecture},
        "parameters": sum(p.numel() for p in net.parameters()),
        "recipe": {"name": recipe, **settings, "pos_weight_used": pos_weight,
                   "epochs_run": len(history),
                   "best_epoch": best_epoch, "seed": seed, "minutes": minutes,
                   "init": Path(init).name if init is not None else None,
                   "stopped_by_time": out_of_time},
        "data": {"path": Path(data_path).name, "seed": meta.get("seed"),
                 "nodes": meta.get("nodes"), "samples": len(samples),
                 "train": len(train_idx), "test": len(val_idx)},
        "metrics_test_split": val, "history": history,
        "sha256": sha256(out_path),
        "versions": {"torch": torch.__version__, "numpy": np.__version__},
        "seconds": time.perf_counter() - started,
    }
    write_json_atomic(out_path.with_suffix(".json"), metadata)
    return metadata


def export_onnx(net: QuadCNN, path) -> None:
    from .model import Probabilities

    net.eval()
    wrapped = Probabilities(net).eval()  # export restores this mode afterwards
    example = torch.zeros(1, 64, net.inputs)
    example[..., :2] = torch.rand(1, 64, 2)

    def write(tmp):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            torch.onnx.export(wrapped, (example,), tmp, dynamo=False, opset_version=17,
                              input_names=["points"], output_names=["probabilities"],
                              dynamic_axes={"points": {0: "batch", 1: "n"},
                                            "probabilities": {0: "batch", 1: "n"}})

    write_atomic(path, write)


def sha256(path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()
