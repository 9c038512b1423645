"""The random-shape robustness campaign:
`python -m quadcnn_wb.bench.robustness [-n 500] [--seed 0] [--workers W] [--timeout 60]`.

Every shape from bench.random_shapes goes through the whole pipeline in a worker process
with a wall-time limit, and every mesh handed back is checked by bench.meshcheck (which
shares no code with the pipeline).  Outcomes: valid block-structured mesh, valid stand-in
mesh (gmsh quads where no block structure was found), partly block-structured (the
faces that are no blocks got unstructured quads), refused (the input is not a valid
domain: the reason is the validator's), and the ones that must never happen — failed (an
error other than a refusal), invalid mesh, crash, hang.  Printed: counts by outcome and
reason, and the worst elements; the exit status is 1 when any must-never outcome occurred.
"""

from __future__ import annotations

import argparse
import multiprocessing
import sys
import time
from collections import Counter

import numpy as np

NEVER = ("failed", "invalid mesh", "crash", "hang")


def run_one(seed: int, index: int) -> dict:
    """Draw shape `index` of campaign `seed`, mesh it, check it; never raises."""
    from ..core.input.domain import DomainError, domain_from_json
    from ..core.pipeline import mesh_domain
    from .meshcheck import MeshDefect, check_domain_mesh
    from .random_shapes import random_shape

    rng = np.random.default_rng([seed, index])
    data, drawn = random_shape(rng)
    row = {"index": index, **drawn}
    start = time.perf_counter()
    try:
        domain = domain_from_json(data)
    except DomainError as exc:
        return {**row, "outcome": "refused", "reason": _reason(exc)}
    try:
        result = mesh_domain(domain)
    except Exception as exc:  # every error here is a finding of the campaign
        return {**row, "outcome": "failed", "reason": f"{type(exc).__name__}: {_reason(exc)}"}
    row["seconds"] = time.perf_counter() - start
    mesh = result.mesh
    try:
        check_domain_mesh(domain, mesh)
    except MeshDefect as exc:
        return {**row, "outcome": "invalid mesh", "reason": str(exc)}
    outcome = "valid, block-structured" if result.structured else \
        "valid, partly block-structured" if result.structured_share > 0 else \
        "valid, gmsh stand-in"
    return {**row, "outcome": outcome, "reason": "" if result.structured else
            _reason(result.problem), "quads": int(len(mesh.quads)),
            "structured_share": float(result.structured_share),
            "min_sj": float(result.quality["min_scaled_jacobian"]),
            "irregular": int(result.quality["irregular_vertices"]),
            "singular": len(result.reference.field.singularities)}


def _reason(exc) -> str:
    """The kind of problem without the numbers and names that differ between shapes."""
    text = " ".join(str(exc).split())
    if text.startswith("no block structure (") and ")" in text:
        text = text[len("no block structure ("):].rsplit(")", 1)[0]
    for sep in (":", " (", " at ", " near "):
        if sep in text[1:]:
            text = text.split(sep)[0] if not text.startswith(sep) else text
    return text[:90]


def _run_one_packed(args):
    return run_one(*args)


def campaign(n: int, seed: int, workers: int, timeout: float, progress=True) -> list:
    """Rows in index order; a shape that exceeds `timeout` seconds is recorded as a hang
    and its worker replaced, a worker that dies is recorded as a crash."""
    rows = {}
    pending = list(range(n))
    context = multiprocessing.get_context("spawn")
    while pending:
        with context.Pool(workers, maxtasksperchild=20) as pool:
            jobs = {i: pool.apply_async(run_one, (seed, i)) for i in pending}
            pending = []
            started = time.perf_counter()
            for i, job in jobs.items():
                if pending:  # a hang poisoned this pool: re-run the rest in a new one
                    pending.append(i)
                    continue
                left = max(1.0, timeout * (1 + list(jobs).index(i) / workers)
                           - (time.perf_counter() - started))
                try:
                    rows[i] = job.get(timeout=left)
                except multiprocessing.TimeoutError:
                    rows[i] = {"index": i, "outcome": "hang",
                               "reason": f"no result within {timeout:g} s"}
                    pending.append(None)
                except Exception as exc:
                    rows[i] = {"index": i, "outcome": "crash",
                               "reason": f"{type(exc).__name__}: {_reason(exc)}"}
                if progress:
                    sys.stderr.write(f"\r{len(rows)}/{n} shapes ")
                    sys.stderr.flush()
            pending = [i for i in pending if i is not None]
            pool.terminate()
    if progress:
        sys.stderr.write("\n")
    return [rows[i] for i in range(n)]


def report(rows) -> str:
    lines = [f"{len(rows)} random shapes"]
    outcomes = Counter(r["outcome"] for r in rows)
    for outcome, count in outcomes.most_common():
        lines.append(f"  {outcome}: {count}")
        reasons = Counter(r["reason"] for r in rows if r["outcome"] == outcome and r["reason"])
        for reason, k in reasons.most_common(8):
            lines.append(f"      {k} × {reason}")
    meshed = [r for r in rows if r["outcome"].startswith("valid")]
    if meshed:
        worst = sorted(meshed, key=lambda r: r["min_sj"])[:5]
        lines.append("  worst elements (min scaled Jacobian, shape index, corners, holes, "
                     "scale):")
        for r in worst:
            lines.append(f"      {r['min_sj']:.3f}  #{r['index']}  {r['corners']} corners, "
                         f"{r['holes']} holes, scale {r['scale']:.3g}, {r['outcome']}")
        structured = [r for r in meshed if r["outcome"] == "valid, block-structured"]
        extra = sum(r["irregular"] > r["singular"] for r in structured)
        share = np.mean([r["structured_share"] for r in meshed])
        lines.append(f"  share of the quads in blocks, mean over meshed shapes: {share:.3f}")
        times = [r["seconds"] for r in meshed]
        lines.append(f"  block-structured meshes with irregular vertices beyond the singular "
                     f"points: {extra} of {len(structured)}")
        lines.append(f"  time per shape: median {np.median(times):.2f} s, max "
                     f"{max(times):.2f} s")
    never = sum(outcomes[k] for k in NEVER)
    lines.append(f"  must-never outcomes (failed, invalid mesh, crash, hang): {never}")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-n", type=int, default=500)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--workers", type=int, default=multiprocessing.cpu_count())
    parser.add_argument("--timeout", type=float, default=60.0)
    args = parser.parse_args(argv)
    rows = campaign(args.n, args.seed, args.workers, args.timeout)
    print(report(rows))
    return 1 if any(r["outcome"] in NEVER for r in rows) else 0


if __name__ == "__main__":
    raise SystemExit(main())
