"""Training a model for one design: its variants (made by FreeCAD from the sketch's
dimensions), the augmentation of the learning issue, the dataset, the network.

`python -m quadcnn_wb.learn.design_train VARIANTS.json -o MODEL.onnx [--samples 400]`
VARIANTS.json: {"name": ..., "domains": [Domain JSON, ...]}, the first being the design
as it is.  Runs as a separate process so FreeCAD stays responsive; it prints one line
`progress FRACTION TEXT` per step of work on stdout (what the GUI's progress bar shows) and
`model PATH` at the end; errors as one `error: ...` line, exit status 2.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

GENERATION_SHARE = 0.35  # of the progress bar: the rest is training
RECIPE = "rays"  # learns in one epoch what "fast" needs twenty for (docs/learning.md)


def say(fraction: float, text: str) -> None:
    print(f"progress {min(max(fraction, 0.0), 1.0):.4f} {text}", flush=True)


def run(variants_path, out, samples: int, epochs: int, seed: int, minutes, workers) -> Path:
    from ..core.field.reference import numerical_reference
    from ..core.input.domain import domain_from_json
    from ..infer.signature import topology_signature
    from .dataset import Variants, generate, save_dataset
    from .train import train

    spec = json.loads(Path(variants_path).read_text())
    domains = spec["domains"]
    if not domains:
        raise ValueError(f"{variants_path}: no design variants")
    design = domain_from_json(domains[0])
    counts = numerical_reference(design).field.valences()
    variants = Variants(tuple(domains), (counts[3], counts[5]), spec.get("name", "design"))
    say(0.0, f"{len(domains)} variants; generating {samples} samples")
    data, dropped = generate(variants, samples, seed, workers=workers,
                             progress=lambda d, n: say(GENERATION_SHARE * d / n,
                                                       f"sample {d}/{n}"))
    if len(data) < 10:
        hint = "narrow the ranges" if dropped else "ask for more samples"
        raise ValueError(f"only {len(data)} usable samples of {samples}, at least 10 needed "
                         f"(dropped: {dict(dropped) or 'none'}); {hint}")
    out = Path(out)
    data_path = out.with_suffix(".npz")
    topology = topology_signature(design)
    save_dataset(data_path, data, {"family": f"design:{variants.name}", "seed": seed,
                                   "topology": topology, "dropped": dict(dropped)})
    train(data_path, out, epochs=epochs, seed=seed, recipe=RECIPE, threads=1,
          progress=False, minutes=minutes, patience=epochs,
          report=lambda f, text: say(GENERATION_SHARE + (1 - GENERATION_SHARE) * f, text),
          meta_extra={"design": variants.name, "variants": len(domains)})
    data_path.unlink(missing_ok=True)
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("variants")
    parser.add_argument("-o", "--output", required=True)
    parser.add_argument("--samples", type=int, default=400)
    parser.add_argument("--epochs", type=int, default=8)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--minutes", type=float, default=None)
    parser.add_argument("--workers", type=int, default=None)
    args = parser.parse_args(argv)
    try:
        import torch  # noqa: F401
    except ImportError:
        print("error: training needs PyTorch: .venv/bin/pip install -e '.[train]'",
              file=sys.stderr)
        return 2
    try:
        path = run(args.variants, args.output, args.samples, args.epochs, args.seed,
                   args.minutes, args.workers)
    except (OSError, ValueError, KeyError) as exc:
        print(f"error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    print(f"model {path}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
