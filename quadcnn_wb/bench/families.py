"""Fresh random members of every shape family through the numerical path:
`python -m quadcnn_wb.bench.families [-n 200] [--seed 2027] [--workers 2] [--family F ...]
[--poses]`.

The families are the shapes the method is built for, so every member should come out
fully block-structured, valid (bench.meshcheck, which shares no code with the pipeline)
and with no irregular vertex but the field's singular points (and the corners the layout
reads where the boundary is smooth: small concave fillets, small round holes' squares).
Printed per family: how many members did, the mean share of quads in blocks, the members
with extra irregular vertices, the worst element, the median and slowest time, and the
first few that did not (with the pipeline's reason), so a failure can be reproduced by
its index.  With --poses every member is also meshed turned by odd angles, moved by 1e4
of its size, mirrored and rescaled by 1e-3 and 1e3 (POSES), and the members whose block
count, quad count and irregular vertices are the same in every pose are counted ("same in poses").
"""

from __future__ import annotations

import argparse
import multiprocessing
import statistics
import time

import numpy as np

POSES = (  # (degrees, mirrored, scale, shift in part sizes)
    (37.0, False, 1.0, 0.0), (0.0, False, 1.0, 1e4), (211.0, True, 1.0, 0.0),
    (131.0, False, 1e-3, 3.0), (73.0, True, 1e3, -7.0))


def pose_signature(result) -> tuple:
    """What a turned, moved, mirrored or rescaled copy must share with the part."""
    q = result.quality
    return result.structured_share, q["blocks"], q["quads"], q["irregular_vertices"]


def poses_differing(data: dict, base, size: float | None = None) -> list:
    """The POSES (indices) whose copy of the domain JSON ``data`` gets other blocks, quads,
    irregular vertices or structured share than ``base``, meshed at ``size`` scaled with
    the copy (the copy's default size where None)."""
    from ..core.input.domain import domain_from_json
    from ..core.input.transform import similarity, transform_domain_json
    from ..core.pipeline import mesh_domain

    extent = base.domain.size
    differing = []
    for k, (degrees, mirrored, scale, shift) in enumerate(POSES):
        moved = transform_domain_json(data, similarity(degrees, scale, mirrored),
                                      np.full(2, shift * extent * scale))
        result = mesh_domain(domain_from_json(moved),
                             size=None if size is None else size * scale)
        if pose_signature(result) != pose_signature(base):
            differing.append(k)
    return differing


def same_in_every_pose(data: dict, base) -> bool:
    """Whether every POSES copy of the domain JSON ``data`` gets ``base``'s blocks, quads
    and irregular vertices."""
    return not poses_differing(data, base)


def run_member(name: str, seed: int, index: int, poses: bool = False) -> dict:
    """Member `index` of family `name` for campaign `seed`, meshed and checked."""
    from ..core.pipeline import mesh_domain
    from ..learn.families import family
    from .meshcheck import MeshDefect, check_domain_mesh

    params, domain = family(name).sample(np.random.default_rng([seed, index]))
    start = time.perf_counter()
    result = mesh_domain(domain)
    seconds = time.perf_counter() - start
    try:
        check_domain_mesh(domain, result.mesh)
        defect = ""
    except MeshDefect as exc:
        defect = str(exc)
    return {"family": name, "index": index, "seconds": seconds, "valid": not defect,
            "defect": defect, "structured": result.structured,
            "share": result.structured_share, "problem": result.problem,
            "min_sj": result.quality["min_scaled_jacobian"],
            "extra_irregular": result.quality["irregular_vertices"]
            - len(result.reference.field.singularities) - result.feature_corners,
            "same_in_poses": same_in_every_pose(family(name).build(params), result)
            if poses else None}


def _packed(args):
    return run_member(*args)


def report(rows: list) -> str:
    posed = all(r["same_in_poses"] is not None for r in rows)
    lines = ["family       members  structured  valid  mean share  extra irregular  "
             "worst SJ  median s  max s" + ("  same in poses" if posed else "")]
    for name in sorted({r["family"] for r in rows}):
        own = [r for r in rows if r["family"] == name]
        lines.append(
            f"{name:12s} {len(own):7d}  {sum(r['structured'] for r in own):10d}  "
            f"{sum(r['valid'] for r in own):5d}  {np.mean([r['share'] for r in own]):10.3f}  "
            f"{sum(r['extra_irregular'] > 0 for r in own):15d}  "
            f"{min(r['min_sj'] for r in own):8.3f}  "
            f"{statistics.median(r['seconds'] for r in own):8.2f}  "
            f"{max(r['seconds'] for r in own):5.2f}"
            + (f"  {sum(r['same_in_poses'] for r in own):13d}" if posed else ""))
        for r in [r for r in own if not (r["structured"] and r["valid"])][:5]:
            lines.append(f"    #{r['index']}: {r['defect'] or r['problem'][:110]}")
    return "\n".join(lines)


def main(argv=None) -> int:
    from ..learn.families import FAMILIES

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-n", type=int, default=200, help="members per family")
    parser.add_argument("--seed", type=int, default=2027)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--family", nargs="*", default=sorted(FAMILIES))
    parser.add_argument("--poses", action="store_true",
                        help="also check every member in turned, moved, mirrored and "
                             "rescaled copies")
    args = parser.parse_args(argv)
    jobs = [(name, args.seed, k, args.poses) for name in args.family for k in range(args.n)]
    with multiprocessing.get_context("spawn").Pool(args.workers) as pool:
        rows = pool.map(_packed, jobs, chunksize=4)
    print(report(rows))
    return 0 if all(r["structured"] and r["valid"] and r["same_in_poses"] is not False
                    for r in rows) else 1


if __name__ == "__main__":
    raise SystemExit(main())
