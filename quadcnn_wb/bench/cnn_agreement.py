"""How far the cnn path can be trusted, and what it saves:
`python -m quadcnn_wb.bench.cnn_agreement [--samples 40] [--seed 9100] [MODEL.onnx ...]`.

For each model (default: the shipped ones), fresh members of its family (a seed never used
for training data), turned, mirrored, scaled by 1 to 1000 and moved, are meshed twice on
the same background mesh and field: once with numerical tracing, once from the model's
labels.  Printed per family: the share rebuilt with no fallback at all (over all members,
and over those whose numerical partition is valid: where tracing itself gives no block
structure, the cnn path's partition fails too and everything is retraced), the mean share
of walks the checks rejected (each traced numerically instead), the mean share of
streamlines in the final mesh rebuilt from labels (less when a partition failed and
everything was retraced), the share whose
block structure (blocks, partition edges and vertices) equals the numerical one, the
symmetric Hausdorff distance between the two sets of streamlines as a share of the
bounding-box diagonal (median and worst), the share of valid meshes on each path, and the
median times of prediction + reconstruction against numerical tracing, measured in the
same run (the paper: 0.782 s against 1.644 s).

`--labels reference` rebuilds from the numerical reference's own labels instead of the
model's, and `--labels rays` from the labels' rule applied to the ray hints: what the
reconstruction makes of perfect (or model-free) labels, which tells its failures apart
from the network's.  The times are then not the cnn path's and are not printed.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from scipy.spatial.distance import directed_hausdorff

from ..core.field.labels import frame_labels
from ..core.input.domain import domain_from_json
from ..core.input.transform import similarity, transform_domain_json
from ..core.layout.tracing import trace_streamlines
from ..core.pipeline import mesh_domain
from ..infer.cnn import cnn_streamlines
from ..infer.encoding import model_input, swap_labels
from ..infer.models import model_paths
from ..infer.predictor import INPUT_WIDTHS, Predictor
from ..infer.rays import hint_labels
from ..infer.reconstruct import reconstruct_streamlines
from ..learn.families import family
from .common import model_options, print_table_header


def fresh_member(name: str, rng) -> object:
    """A family member in a random pose and at a random scale from 1 to 1000."""
    _, domain = family(name).sample(rng)
    matrix = similarity(rng.uniform(0, 360), scale=10 ** rng.uniform(0, 3),
                        mirror=bool(rng.integers(2)))
    shift = rng.uniform(-500, 500, size=2)
    return domain_from_json(transform_domain_json(domain.to_json(), matrix, shift))


def dense_points(lines, spacing: float) -> np.ndarray:
    out = []
    for line in lines:
        p = line.points
        seg = np.hypot(*np.diff(p, axis=0).T)
        s = np.concatenate([[0.0], np.cumsum(seg)])
        t = np.linspace(0.0, s[-1], max(2, int(s[-1] / spacing) + 1))
        out.append(np.column_stack([np.interp(t, s, p[:, 0]), np.interp(t, s, p[:, 1])]))
    return np.concatenate(out) if out else np.zeros((0, 2))


def hausdorff_share(a_lines, b_lines, diagonal: float) -> float:
    a = dense_points(a_lines, diagonal / 2000)
    b = dense_points(b_lines, diagonal / 2000)
    if not len(a) or not len(b):
        return 0.0 if len(a) == len(b) else 1.0
    return max(directed_hausdorff(a, b)[0], directed_hausdorff(b, a)[0]) / diagonal


def structure(result) -> tuple:
    p = result.partition
    return (len(p.blocks), len(p.edges), len(p.vertices)) if result.structured else ()


def label_source(model: Path, labels: str):
    """The learned_streamlines callable of mesh_domain for a label source (see --labels)."""
    if labels == "model":
        return cnn_streamlines(model, threads=1)  # its own session, created once

    def source(domain, background, field):
        if labels == "reference":
            found = frame_labels(background, field.frames,
                                 trace_streamlines(domain, background, field))
        else:
            x, swapped = model_input(background, field, max(INPUT_WIDTHS))
            found = swap_labels(hint_labels(x), swapped)
        return reconstruct_streamlines(domain, background, field, found)

    return source


def compare(model: Path, samples: int, seed: int, nodes: int, labels: str = "model") -> dict:
    name = Predictor(model).metadata["family"]
    rebuild = label_source(model, labels)
    walks = {}

    def source(domain, background, field):  # counts the walks the checks rejected
        lines, problems = rebuild(domain, background, field)
        total = sum(len(src.directions)
                    for src in (*field.singularities, *field.corner_sources))
        walks.update(total=total, rejected=len(problems))
        return lines, problems

    rng = np.random.default_rng(seed)
    rows = []
    for _ in range(samples):
        domain = fresh_member(name, rng)
        numerical = mesh_domain(domain, nodes=nodes, method="numerical")
        start = time.perf_counter()
        learned = mesh_domain(domain, nodes=nodes, method="cnn", learned_streamlines=source)
        diagonal = domain.size  # the bounding-box diagonal
        rows.append({
            "no_fallback": not learned.fallback,
            "rebuilt": 1.0 - len(learned.fallback) / max(len(learned.streamlines), 1),
            "walks": walks["rejected"] / max(walks["total"], 1),
            "same_structure": structure(learned) == structure(numerical),
            "hausdorff": hausdorff_share(learned.streamlines, numerical.streamlines, diagonal),
            "valid_cnn": learned.structured,
            "valid_numerical": numerical.structured,
            "t_cnn": learned.timings["reconstruction"],
            "t_numerical": numerical.timings["tracing"],
            "wall_cnn": time.perf_counter() - start,
        })
    return {"family": name, "rows": rows}


def main(argv=None) -> int:
    parser = model_options(__doc__, samples=40, seed=9100)
    parser.add_argument("--nodes", type=int, default=2048)
    parser.add_argument("--labels", choices=("model", "reference", "rays"), default="model",
                        help="rebuild from the model's labels (default), the numerical "
                             "reference's, or the ray hints' rule")
    args = parser.parse_args(argv)
    models = model_paths(args.models)
    print_table_header(["family", "samples", "no fallback (all / numerical valid)",
                        "walks rejected", "lines rebuilt", "same blocks",
                        "Hausdorff median / worst (% diag)", "valid cnn / numerical",
                        "cnn time", "tracing time", "speed-up"])
    for model in models:
        compared = compare(model, args.samples, args.seed, args.nodes, args.labels)
        name, rows = compared["family"], compared["rows"]
        share = {k: np.mean([r[k] for r in rows]) for k in
                 ("no_fallback", "same_structure", "valid_cnn", "valid_numerical")}
        valid = [r["no_fallback"] for r in rows if r["valid_numerical"]]
        h = np.array([r["hausdorff"] for r in rows]) * 100
        t_cnn = float(np.median([r["t_cnn"] for r in rows]))
        t_num = float(np.median([r["t_numerical"] for r in rows]))
        times = (f"{1000 * t_cnn:.1f} ms | {1000 * t_num:.1f} ms | {t_num / t_cnn:.1f}×"
                 if args.labels == "model" else f"– | {1000 * t_num:.1f} ms | –")
        print(f"| {name} | {len(rows)} | {share['no_fallback']:.0%} / "
              f"{np.mean(valid) if valid else 0:.0%} of {len(valid)} | "
              f"{np.mean([r['walks'] for r in rows]):.1%} | "
              f"{np.mean([r['rebuilt'] for r in rows]):.1%} | "
              f"{share['same_structure']:.0%} | {np.median(h):.2f} / {h.max():.2f} | "
              f"{share['valid_cnn']:.0%} / {share['valid_numerical']:.0%} | {times} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
