"""onnxruntime inference time for one 2048-node sample:
`python -m quadcnn_wb.bench.inference_speed [MODEL.onnx ...]`.

Without arguments it times the shipped models in resources/models (or, when there are
none, an untrained network exported on the spot: the graph and its cost are the same).
Prints the median over repeats with 1 and 2 threads; the issue's goal is <= 60 ms here.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

from ..core.field.reference import numerical_reference
from ..core.input.load import load_domain
from ..infer.encoding import model_input
from ..infer.models import model_paths
from ..infer.predictor import INPUT_WIDTHS, Predictor
from .common import EXAMPLES


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("models", nargs="*")
    parser.add_argument("--repeat", type=int, default=20)
    args = parser.parse_args(argv)
    models = model_paths(args.models)
    if not models:
        import torch

        from ..learn.model import QuadCNN
        from ..learn.train import export_onnx

        torch.manual_seed(0)
        models = [Path(tempfile.mkdtemp()) / "untrained.onnx"]
        export_onnx(QuadCNN(), models[0])
    ref = numerical_reference(load_domain(EXAMPLES / "four_hole.json"), labels=False)
    width = max(INPUT_WIDTHS)
    x, _ = model_input(ref.mesh, ref.field, width=width)
    print(f"one sample of {len(x)} points (four_hole)")
    hint_times = []
    for _ in range(args.repeat):
        start = time.perf_counter()
        model_input(ref.mesh, ref.field, width=width)
        hint_times.append(time.perf_counter() - start)
    print(f"{'encoding with ray hints':<24}            median "
          f"{statistics.median(hint_times) * 1e3:6.1f} ms (models of {width} input columns)")
    for model in models:
        for threads in (1, 2):
            predictor = Predictor(model, threads=threads)
            predictor.probabilities(x)  # warm-up
            times = []
            for _ in range(args.repeat):
                start = time.perf_counter()
                predictor.probabilities(x)
                times.append(time.perf_counter() - start)
            print(f"{model.name:<24} {threads} thread(s): median "
                  f"{statistics.median(times) * 1e3:6.1f} ms, max {max(times) * 1e3:6.1f} ms")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
