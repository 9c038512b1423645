"""Our numerical path against gmsh's quasi-structured quad mesher, measured in one run:
`python -m quadcnn_wb.bench.mesh_vs_gmsh`.

Both mesh every bundled example at the same target element size (--size-divisor: the
domain diagonal divided by this, the pipeline's default; the semicircle also at DESIGN.md's
0.05).  gmsh runs Mesh.Algorithm = 11 in-process on the same exact geometry; both meshes
are scored by our own quality code (DESIGN.md scaled Jacobian and irregular vertices).
"""

from __future__ import annotations

import argparse
import statistics

from ..core.input.pose import DEFAULT_SIZE_DIVISOR
from ..core.mesh.gmsh_quads import gmsh_quasi_structured
from ..core.mesh.quadmesh import scaled_jacobians
from ..core.mesh.quality import boundary_quads_expected, irregular_vertices
from ..core.pipeline import mesh_domain
from .common import bundled_examples


def score(domain, nodes, quads, boundary):
    """(quads, worst and mean scaled Jacobian, irregular vertices) of a mesh, by DESIGN.md's
    definitions (our own quality code)."""
    sj = scaled_jacobians(nodes, quads)
    expected = boundary_quads_expected(domain, nodes, boundary)
    irregular = len(irregular_vertices(quads, len(nodes), expected))
    return len(quads), float(sj.min()), float(sj.mean()), irregular


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size-divisor", type=float, default=DEFAULT_SIZE_DIVISOR)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--gmsh-size-factor", type=float, default=1.0,
                        help="give gmsh this times the size (its algorithm 11 splits every "
                        "triangle, so 2 gives about as many quads as ours)")
    args = parser.parse_args(argv)
    cases = [(name, domain, domain.size / args.size_divisor) for name, domain in
             bundled_examples()]
    cases += [("semicircle", domain, 0.05) for name, domain in bundled_examples()
              if name == "semicircle"]
    print(f"{'example':<11} {'size':>7} | {'ours: quads':>11} {'minSJ':>6} {'meanSJ':>6} "
          f"{'irr':>4} {'sing':>4} {'time':>7} | {'gmsh: quads':>11} {'minSJ':>6} "
          f"{'meanSJ':>6} {'irr':>4} {'time':>7} | {'time ratio':>10}")
    for name, domain, size in cases:
        ours_t, peer_t = [], []
        for _ in range(args.repeat):
            result = mesh_domain(domain, size=size)
            ours_t.append(result.timings["total"])
            nodes, quads, boundary, seconds = gmsh_quasi_structured(
                domain, size * args.gmsh_size_factor)
            peer_t.append(seconds)
        q = result.quality
        peer = score(domain, nodes, quads, boundary)
        ours_s, peer_s = statistics.median(ours_t), statistics.median(peer_t)
        print(f"{name:<11} {size:>7.4f} | {q['quads']:>11} {q['min_scaled_jacobian']:>6.3f} "
              f"{q['mean_scaled_jacobian']:>6.3f} {q['irregular_vertices']:>4} "
              f"{len(result.reference.field.singularities):>4} {ours_s:>6.3f}s | "
              f"{peer[0]:>11} {peer[1]:>6.3f} {peer[2]:>6.3f} {peer[3]:>4} {peer_s:>6.3f}s | "
              f"{ours_s / peer_s:>10.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
