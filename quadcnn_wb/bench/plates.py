"""Random machined plates, the part a user meshes most, meshed one by one.

    python -m quadcnn_wb.bench.plates [-n 30] [--seed 1] [--d100] [--gmsh] [--save DIR]

Each member is a rectangle 40 to 300 mm a side, its corners sharp or rounded, with up to
twelve bolt holes and stadium slots of 0.5 mm radius up to an eighth of the plate, at
random places with 0.5 to 5 mm of material between them: every member is valid, and the
figures say how many get a mesh all in blocks.  The campaign's random shapes
(bench.random_shapes) are stars with a hole or two; these are what a machined part
holds, and they found faults the corpus did not have (a grid of small bolt holes left no
background, a slot about an element long made the whole plate fall back).  ``--save``
writes the members that are not all blocks as domain JSON, to look at with
``quadcnn mesh`` or bench.folder.  ``--gmsh`` meshes each member with gmsh's algorithm
11 at the same size too (bench.corpus's peer) and counts the members where ours is all
in blocks with a worst element and irregular vertices at least as good, in less time.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

TRIES = 30  # places tried for each hole before it is left out
GAPS = (0.5, 2.0, 5.0)  # mm of material between two holes, drawn from these


def _arc(centre, radius, a0, a1) -> dict:
    def point(a):
        return [centre[0] + radius * math.cos(a), centre[1] + radius * math.sin(a)]
    return {"arc": [point(a0), point(0.5 * (a0 + a1)), point(a1)]}


def _outline(w, h, r) -> list:
    if r <= 0.0:
        corners = [[0, 0], [w, 0], [w, h], [0, h]]
        return [{"line": [corners[k], corners[(k + 1) % 4]]} for k in range(4)]
    quarter = 0.5 * math.pi
    return [{"line": [[r, 0], [w - r, 0]]}, _arc((w - r, r), r, -quarter, 0.0),
            {"line": [[w, r], [w, h - r]]}, _arc((w - r, h - r), r, 0.0, quarter),
            {"line": [[w - r, h], [r, h]]}, _arc((r, h - r), r, quarter, 2 * quarter),
            {"line": [[0, h - r], [0, r]]}, _arc((r, r), r, 2 * quarter, 3 * quarter)]


def _slot(cx, cy, length, r, horizontal) -> list:
    """A stadium, as CAD files store a milled slot: two lines and two half circles."""
    quarter = 0.5 * math.pi
    if horizontal:
        a, b = (cx - length / 2, cy), (cx + length / 2, cy)
        return [{"line": [[a[0], a[1] - r], [b[0], b[1] - r]]}, _arc(b, r, -quarter, quarter),
                {"line": [[b[0], b[1] + r], [a[0], a[1] + r]]}, _arc(a, r, quarter, 3 * quarter)]
    a, b = (cx, cy - length / 2), (cx, cy + length / 2)
    return [{"line": [[a[0] + r, a[1]], [b[0] + r, b[1]]]}, _arc(b, r, 0.0, 2 * quarter),
            {"line": [[b[0] - r, b[1]], [a[0] - r, a[1]]]}, _arc(a, r, 2 * quarter, 4 * quarter)]


def random_plate(rng: np.random.Generator) -> dict:
    """One member: domain JSON in mm."""
    w, h = rng.uniform(40, 300), rng.uniform(40, 300)
    rounding = rng.uniform(1, 0.3 * min(w, h)) if rng.random() < 1 / 3 else 0.0
    loops = [_outline(w, h, rounding)]
    placed = []  # (x, y, reach from the centre)
    for _ in range(int(rng.integers(0, 13))):
        for _ in range(TRIES):
            slot = rng.random() < 1 / 3
            r = rng.uniform(0.5, 0.12 * min(w, h))
            length = rng.uniform(r, 6 * r) if slot else 0.0
            horizontal = rng.random() < 0.5
            reach = r + length / 2
            margin = reach + 1 + rounding / 3
            if 2 * margin >= min(w, h):
                continue
            x, y = rng.uniform(margin, w - margin), rng.uniform(margin, h - margin)
            gap = GAPS[int(rng.integers(0, len(GAPS)))]
            if rounding and min(x, w - x) < rounding and min(y, h - y) < rounding:
                continue  # in a rounded corner's square: it could cut the arc
            if all(math.hypot(x - px, y - py) > reach + other + gap for px, py, other in placed):
                placed.append((x, y, reach))
                loops.append(_slot(x, y, length, r, horizontal) if slot
                             else [{"circle": {"center": [x, y], "radius": r}}])
                break
    return {"units": "mm", "loops": loops}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-n", type=int, default=30, help="members")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--d100", action="store_true", help="mesh at diameter / 100")
    parser.add_argument("--gmsh", action="store_true", help="compare with gmsh alg. 11")
    parser.add_argument("--save", type=Path, help="write members not all in blocks here")
    args = parser.parse_args(argv)
    from ..core.input.domain import domain_from_json
    from ..core.input.pose import diameter
    from ..core.pipeline import mesh_domain
    from .corpus import peer

    rng = np.random.default_rng(args.seed)
    whole, better, seconds = 0, 0, []
    for k in range(args.n):
        data = random_plate(rng)
        domain = domain_from_json(data)
        clock = time.perf_counter()
        result = mesh_domain(domain, size=diameter(domain) / 100 if args.d100 else None)
        seconds.append(time.perf_counter() - clock)
        q = result.quality
        whole += result.structured_share >= 1.0
        line = (f"{k:4d} loops {len(data['loops']):3d}  share {result.structured_share:.3f}  "
                f"irr {q['irregular_vertices']:4d}  sj {q['min_scaled_jacobian']:.3f}  "
                f"quads {q['quads']:6d}  {seconds[-1]:.2f}s")
        if args.gmsh:
            theirs = peer(domain, result.size, 1, 0)
            better += bool(result.structured_share >= 1.0
                           and q["min_scaled_jacobian"] >= theirs["min_sj"]
                           and q["irregular_vertices"] <= theirs["irregular"]
                           and seconds[-1] < theirs["time"])
            line += (f"  | gmsh irr {int(theirs['irregular']):4d}  sj {theirs['min_sj']:.3f}  "
                     f"quads {int(theirs['quads']):6d}  {theirs['time']:.2f}s")
        print(line, flush=True)
        if args.save and result.structured_share < 1.0:
            args.save.mkdir(parents=True, exist_ok=True)
            (args.save / f"plate_{args.seed}_{k}.json").write_text(json.dumps(data))
    print(f"{'d100' if args.d100 else 'default'}: all in blocks {whole}/{args.n}, "
          f"median {np.median(seconds):.2f} s, slowest {max(seconds):.2f} s"
          + (f"; all in blocks, worst element and irregular vertices at least gmsh's, "
             f"faster: {better}/{args.n}" if args.gmsh else ""))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
