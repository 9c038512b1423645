"""Time the numerical reference: `python -m quadcnn_wb.bench.field_speed`.

Median wall times per bundled example at 2048 nodes (one core) of the cross field with
its singular points, the streamline tracing and the labels, next to the paper's figure
for numerical tracing on its four-hole model (1.644 s) and the issue's goals
(field + singular points <= 0.1 s, tracing <= 0.2 s).
"""

from __future__ import annotations

import statistics

from ..core.field.background import background_mesh
from ..core.field.reference import numerical_reference
from .common import bundled_examples, parse_options

PAPER_TRACING_SECONDS = 1.644


def main(argv=None) -> int:
    args = parse_options(__doc__, argv, repeat=9)
    print(f"{'example':<12} {'nodes':>6} {'sing':>5} {'lines':>6} {'field+sing':>11} "
          f"{'tracing':>9} {'labels':>8} {'paper/ours tracing':>19}")
    for name, domain in bundled_examples():
        mesh = background_mesh(domain, nodes=args.nodes)
        runs = [numerical_reference(domain, mesh=mesh) for _ in range(args.repeat)]
        med = {k: statistics.median(r.timings[k] for r in runs)
               for k in ("field", "tracing", "labels")}
        ref = runs[0]
        print(f"{name:<12} {mesh.n_nodes:>6} {len(ref.field.singularities):>5} "
              f"{len(ref.streamlines):>6} {med['field'] * 1e3:>9.1f}ms "
              f"{med['tracing'] * 1e3:>7.1f}ms {med['labels'] * 1e3:>6.1f}ms "
              f"{PAPER_TRACING_SECONDS / med['tracing']:>18.1f}x")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
