"""The paper's Table 2 with our figures beside it:
`python -m quadcnn_wb.bench.table2 [--samples 400] [--seed 9001] [MODEL.onnx ...]`.

For each model (default: the shipped ones in resources/models), fresh test samples of its
family are generated with a seed never used for training data, labelled by the numerical
reference, and compared with the model's prediction (DESIGN.md metric definitions).
The last column is what the ray hints alone give on the same samples (infer.rays: the
labels' rule applied to the coarse rays), the baseline a model of the "rays" recipe must
beat: where it is as good as the model, the rays did the work, not the network.
"""

from __future__ import annotations

from ..infer.metrics import Confusion
from ..infer.models import model_paths
from ..infer.predictor import Predictor
from ..infer.rays import hint_labels
from ..learn.dataset import generate
from .common import model_options, print_table_header

PAPER = {"concave": (0.852, 0.981), "four_hole": (0.821, 0.965)}


def main(argv=None) -> int:
    parser = model_options(__doc__, samples=400, seed=9001)
    parser.add_argument("--workers", type=int, default=None)
    args = parser.parse_args(argv)
    models = model_paths(args.models)
    print_table_header(["topology", "data size", "IoU (paper)", "accuracy (paper)",
                        "IoU (ours)", "accuracy (ours)", "mIoU", "all-zeros accuracy",
                        "test samples", "hints alone IoU / accuracy"])
    for model in models:
        predictor = Predictor(model, threads=2)
        family = predictor.metadata["family"]
        samples, _ = generate(family, args.samples, args.seed, workers=args.workers,
                              progress=False)
        confusion, hinted = Confusion(), Confusion()
        for sample in samples:
            confusion.add(predictor.labels(sample.x), sample.y)
            hinted.add(hint_labels(sample.x), sample.y)
        m = confusion.metrics(len(samples))
        b = hinted.metrics(len(samples))
        paper_iou, paper_acc = PAPER.get(family, ("–", "–"))
        size = predictor.metadata.get("data", {}).get("samples", "?")
        print(f"| {family} | {size} | {paper_iou} | {paper_acc} | {m['iou']:.3f} | "
              f"{m['accuracy']:.3f} | {m['miou']:.3f} | {m['zero_baseline_accuracy']:.3f} | "
              f"{m['samples']} | {b['iou']:.3f} / {b['accuracy']:.3f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
