"""Label metrics as DESIGN.md defines them, from confusion counts over frame vectors.

Every frame vector is one sample (two per node); label 1 is the foreground.
"""

from __future__ import annotations

import numpy as np


class Confusion:
    def __init__(self):
        self.tp = self.fp = self.fn = self.tn = 0

    def add(self, predicted, truth) -> None:
        p = np.asarray(predicted).astype(bool).ravel()
        t = np.asarray(truth).astype(bool).ravel()
        self.tp += int(np.sum(p & t))
        self.fp += int(np.sum(p & ~t))
        self.fn += int(np.sum(~p & t))
        self.tn += int(np.sum(~p & ~t))

    def metrics(self, samples: int) -> dict:
        total = self.tp + self.fp + self.fn + self.tn
        fg_union = self.tp + self.fp + self.fn
        bg_union = self.tn + self.fp + self.fn
        iou = self.tp / fg_union if fg_union else 1.0
        bg_iou = self.tn / bg_union if bg_union else 1.0
        return {
            "accuracy": (self.tp + self.tn) / total if total else 0.0,
            "iou": iou,
            "miou": 0.5 * (iou + bg_iou),
            "precision": self.tp / (self.tp + self.fp) if self.tp + self.fp else 0.0,
            "recall": self.tp / (self.tp + self.fn) if self.tp + self.fn else 0.0,
            "zero_baseline_accuracy": (self.tn + self.fp) / total if total else 0.0,
            "samples": samples,
        }
