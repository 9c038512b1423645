"""Time background meshing in-process: `python -m quadcnn_wb.bench.background_speed`.

For each bundled example, the median wall time of `background_mesh` (domain already
loaded, gmsh initialised and finalised inside every call, size search included) next to
the peer measured in the same run: one bare gmsh `generate(2)` at the element size our
search settled on, i.e. what meshing costs when the right size is known in advance.
"""

from __future__ import annotations

import statistics
import time

import gmsh

from ..core.field.background import GMSH_ALGORITHM, background_mesh
from ..core.gmsh_geometry import build_geometry
from ..core.gmsh_session import gmsh_session
from ..core.input.pose import canonical_pose
from .common import bundled_examples, parse_options


def bare_gmsh_seconds(domain, h: float) -> float:
    with gmsh_session() as session:
        build_geometry(domain, canonical_pose(domain))
        for name, value in (("Mesh.Algorithm", GMSH_ALGORITHM), ("Mesh.MeshSizeFromPoints", 0),
                            ("Mesh.MeshSizeFromCurvature", 0), ("Mesh.Smoothing", 0),
                            ("Mesh.MeshSizeMin", h), ("Mesh.MeshSizeMax", h)):
            session.set(name, value)
        start = time.perf_counter()
        gmsh.model.mesh.generate(2)
        return time.perf_counter() - start


def main(argv=None) -> int:
    args = parse_options(__doc__, argv, repeat=15)
    print(f"{'example':<12} {'nodes':>6} {'ours median':>12} {'ours max':>9} "
          f"{'bare gmsh':>10} {'ratio':>6}")
    for name, domain in bundled_examples():
        ours, peer, mesh = [], [], None
        for _ in range(args.repeat):
            start = time.perf_counter()
            mesh = background_mesh(domain, nodes=args.nodes)
            ours.append(time.perf_counter() - start)
            peer.append(bare_gmsh_seconds(domain, mesh.element_size / domain.size))
        med, bare = statistics.median(ours), statistics.median(peer)
        print(f"{name:<12} {mesh.n_nodes:>6} {med * 1e3:>10.1f}ms {max(ours) * 1e3:>7.1f}ms "
              f"{bare * 1e3:>8.1f}ms {med / bare:>6.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
