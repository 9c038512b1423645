"""Running a trained model with onnxruntime: the session is created once per model."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .encoding import model_input, swap_labels

DEFAULT_THRESHOLD = 0.5
INPUT_WIDTHS = (4, 8, 10)  # the paper's (x, y, v1x, v1y); with 4 or all 6 ray hints


class ModelError(ValueError):
    """A model file that is missing, unreadable or not a QuadCNN model."""


class Predictor:
    def __init__(self, model_path, threads: int = 1):
        import onnxruntime as ort

        self.path = Path(model_path)
        if not self.path.is_file():
            raise ModelError(f"{self.path}: no such model file")
        options = ort.SessionOptions()
        options.intra_op_num_threads = threads
        options.inter_op_num_threads = 1
        options.log_severity_level = 3
        try:
            self.session = ort.InferenceSession(str(self.path), options,
                                                providers=["CPUExecutionProvider"])
        except Exception as exc:
            raise ModelError(f"{self.path}: not a readable ONNX model "
                             f"({str(exc).splitlines()[0][:200]})") from None
        inputs = self.session.get_inputs()
        if len(inputs) != 1 or inputs[0].shape[-1] not in INPUT_WIDTHS:
            raise ModelError(f"{self.path}: expects {[i.shape for i in inputs]}, not the "
                             "QuadCNN input [batch, points, 4] (or 8 or 10 with the ray hints)")
        self.input_name = inputs[0].name
        self.inputs = int(inputs[0].shape[-1])
        self.metadata = load_metadata(self.path)
        self.threshold = float(self.metadata.get("threshold", DEFAULT_THRESHOLD))

    def probabilities(self, x: np.ndarray) -> np.ndarray:
        """(N, ≥ inputs) encoded points -> (N, 2) probabilities of label 1 for v1 and v2.

        Columns past the model's width are left out (a data set carries the hints
        whether the model reads them or not)."""
        x = np.asarray(x, dtype=np.float32)
        if x.shape[-1] < self.inputs:
            raise ModelError(f"{self.path.name} takes {self.inputs} input columns, the data "
                             f"has {x.shape[-1]} (regenerate it with 'quadcnn dataset')")
        batch = np.ascontiguousarray(x[None, :, :self.inputs])
        return self.session.run(None, {self.input_name: batch})[0][0]

    def labels(self, x: np.ndarray) -> np.ndarray:
        return (self.probabilities(x) >= self.threshold).astype(np.uint8)

    def field_labels(self, mesh, field) -> np.ndarray:
        """(N, 2) labels of the field's own (v1, v2): encoded, predicted, put back."""
        x, swapped = model_input(mesh, field, self.inputs)
        return swap_labels(self.labels(x), swapped)


def metadata_path(model_path) -> Path:
    return Path(model_path).with_suffix(".json")


def load_metadata(model_path) -> dict:
    path = metadata_path(model_path)
    if not path.is_file():
        return {}
    try:
        return json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise ModelError(f"{path}: unreadable model metadata ({exc})") from None
