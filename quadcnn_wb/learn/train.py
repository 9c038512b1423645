"""Training, validation and ONNX export: `quadcnn train DATA -o MODEL.onnx`.

Recipes:
- "paper" (default, §3.2): loss 0.5 * cross-entropy + 0.5 * dice on the sigmoid outputs,
  SGD with learning rate 1e-3 and momentum 0.9, batch 4.
- "fast": the same loss with the cross-entropy weighted 4:1 towards the rare label 1,
  AdamW (3e-3) with a cosine schedule.
80/20 split by the seed; the model with the best validation IoU is kept (early stop after
`patience` epochs without improvement), checkpointed every epoch, exported to ONNX (opset
17, dynamic batch and point count) with a metadata JSON beside it.
"""

from __future__ import annotations

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
from .dataset import load_dataset
from .model import QuadCNN, knn

RECIPES = {
    "paper": {"optimizer": "sgd", "lr": 1e-3, "momentum": 0.9, "batch": 4, "pos_weight": 1.0,
              "schedule": "constant"},
    "fast": {"optimizer": "adamw", "lr": 3e-3, "batch": 4, "pos_weight": 4.0,
             "schedule": "cosine", "weight_decay": 1e-4},
}


def loss_fn(logits: torch.Tensor, target: torch.Tensor, pos_weight: float) -> torch.Tensor:
    """0.5 * (weighted) binary cross-entropy + 0.5 * dice, as the paper's §3.2."""
    bce = torch.nn.functional.binary_cross_entropy_with_logits(
        logits, target, pos_weight=torch.tensor(pos_weight))
    z = torch.sigmoid(logits)
    dice = 1 - 2 * ((z * target).sum() + 1e-5) / ((z * z).sum() + (target * target).sum()
                                                  + 1e-5)
    return 0.5 * bce + 0.5 * dice


def split(n: int, seed: int, fraction: float = 0.2):
    order = np.random.default_rng(seed).permutation(n)
    n_val = max(1, int(round(fraction * n))) if n > 1 else 0
    return np.sort(order[n_val:]), np.sort(order[:n_val])


def _batches(samples, indices, batch: int, rng):
    order = rng.permutation(indices)
    for start in range(0, len(order), batch):
        chosen = [samples[i] for i in order[start:start + batch]]
        n = min(len(s.x) for s in chosen)  # crop to a common point count
        picks = [np.sort(rng.choice(len(s.x), n, replace=False)) if len(s.x) > n
                 else np.arange(n) for s in chosen]
        x = np.stack([s.x[p] for s, p in zip(chosen, picks)])
        y = np.stack([s.y[p] for s, p in zip(chosen, picks)]).astype(np.float32)
        yield torch.from_numpy(x), torch.from_numpy(y)


def evaluate_torch(net, samples, indices, threshold: float = 0.5) -> dict:
    net.eval()
    confusion = Confusion()
    with torch.no_grad():
        for i in indices:
            prob = torch.sigmoid(net(torch.from_numpy(samples[i].x[None])))[0].numpy()
            confusion.add(prob >= threshold, samples[i].y)
    return confusion.metrics(len(indices))


def train(data_path, out_path, epochs: int = 30, seed: int = 0, recipe: str = "paper",
          threads: int = 2, patience: int = 6, progress: bool = True) -> dict:
    if recipe not in RECIPES:
        raise ValueError(f"unknown recipe {recipe!r} (known: {', '.join(RECIPES)})")
    settings = RECIPES[recipe]
    samples, meta = load_dataset(data_path)
    if len(samples) < 2:
        raise ValueError(f"{data_path}: needs at least 2 samples, has {len(samples)}")
    torch.manual_seed(seed)
    torch.set_num_threads(threads)
    torch.use_deterministic_algorithms(True, warn_only=True)
    rng = np.random.default_rng(seed)
    train_idx, val_idx = split(len(samples), seed)
    net = QuadCNN()
    if settings["optimizer"] == "sgd":
        opt = torch.optim.SGD(net.parameters(), lr=settings["lr"], momentum=settings["momentum"])
    else:
        opt = torch.optim.AdamW(net.parameters(), lr=settings["lr"],
                                weight_decay=settings["weight_decay"])
    steps_per_epoch = -(-len(train_idx) // settings["batch"])
    schedule = (torch.optim.lr_scheduler.CosineAnnealingLR(opt, epochs * steps_per_epoch)
                if settings["schedule"] == "cosine" else None)
    out_path = Path(out_path)
    checkpoint = out_path.with_suffix(".ckpt.pt")
    best, best_state, best_epoch, history = -1.0, None, 0, []
    started = time.perf_counter()
    for epoch in range(1, epochs + 1):
        net.train()
        losses = []
        for step, (x, y) in enumerate(_batches(samples, train_idx, settings["batch"], rng), 1):
            with torch.no_grad():
                idx = knn(x[..., :2], net.k)
            loss = loss_fn(net(x, idx), y, settings["pos_weight"])
            opt.zero_grad()
            loss.backward()
            opt.step()
            if schedule is not None:
                schedule.step()
            losses.append(float(loss.detach()))
            if progress:
                sys.stderr.write(f"\repoch {epoch}/{epochs} step {step}/{steps_per_epoch} "
                                 f"loss {np.mean(losses):.4f} ")
                sys.stderr.flush()
        val = evaluate_torch(net, samples, val_idx)
        history.append({"epoch": epoch, "loss": float(np.mean(losses)), **val})
        if progress:
            sys.stderr.write(f"| val IoU {val['iou']:.3f} acc {val['accuracy']:.4f} "
                             f"({time.perf_counter() - started:.0f}s)\n")
        if val["iou"] > best:
            best, best_epoch = val["iou"], epoch
            best_state = {k: v.clone() for k, v in net.state_dict().items()}
        state = {"epoch": epoch, "state": net.state_dict(), "best_state": best_state}
        write_atomic(checkpoint, lambda tmp, state=state: torch.save(state, tmp))
        if epoch - best_epoch >= patience:
            break
    net.load_state_dict(best_state)
    val = evaluate_torch(net, samples, val_idx)
    export_onnx(net, out_path)
    metadata = {
        "family": meta.get("family"), "topology": meta.get("topology"),
        "input": ENCODING, "input_shape": ["batch", "points", 4],
        "output": "probabilities of label 1 for v1 and v2", "threshold": 0.5,
        "recipe": {"name": recipe, **settings, "epochs_run": len(history),
                   "best_epoch": best_epoch, "seed": seed},
        "data": {"path": Path(data_path).name, "seed": meta.get("seed"),
                 "samples": len(samples), "train": len(train_idx), "test": len(val_idx)},
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
    example = torch.zeros(1, 64, 4)
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
