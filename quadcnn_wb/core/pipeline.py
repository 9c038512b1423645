"""Domain to block-structured quad mesh in one call; the command line and FreeCAD use this.

The result carries every stage (background mesh, field, streamlines, partition, segment
counts, quad mesh, quality) and the time each took, so callers can draw or export any of
them without recomputing.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .cuts import connecting_cuts
from .domain import Domain
from .partition import Partition, build_partition
from .quadmesh import QuadMesh, build_quad_mesh
from .quality import mesh_quality
from .quantize import quantize
from .reference import Reference, numerical_reference

DEFAULT_SIZE_DIVISOR = 40  # default element size: the domain diagonal / this


@dataclass
class MeshResult:
    domain: Domain
    reference: Reference
    cuts: list
    partition: Partition
    counts: np.ndarray
    mesh: QuadMesh
    quality: dict
    size: float
    method: str = "numerical"
    fallback: list = field(default_factory=list)
    timings: dict = field(default_factory=dict)

    @property
    def streamlines(self) -> list:
        return list(self.reference.streamlines) + list(self.cuts)

    def to_json(self) -> dict:
        """The `mesh` output of DESIGN.md."""
        return {
            "nodes": self.mesh.nodes.tolist(),
            "quads": self.mesh.quads.tolist(),
            "block_of_quad": self.mesh.block_of_quad.tolist(),
            "singularities": [{"xy": s.xy.tolist(), "valence": s.valence}
                              for s in self.reference.field.singularities],
            "streamlines": [line.points.tolist() for line in self.streamlines],
            "method": self.method,
            "fallback": list(self.fallback),
            "quality": dict(self.quality),
            "timings": dict(self.timings),
        }


def default_size(domain: Domain) -> float:
    return domain.size / DEFAULT_SIZE_DIVISOR


def mesh_domain(domain: Domain, size: float | None = None, nodes: int = 2048,
                method: str = "numerical", smoothing: bool = True) -> MeshResult:
    """Run the numerical path end to end."""
    if method not in ("numerical", "auto"):
        raise ValueError(f"method {method!r} is not available")
    size = default_size(domain) if size is None else float(size)
    if not size > 0:
        raise ValueError(f"element size must be positive, got {size}")
    reference = numerical_reference(domain, nodes=nodes, labels=False)
    timings = {k: v for k, v in reference.timings.items() if k != "total"}
    clock = time.perf_counter()
    cuts = connecting_cuts(domain, reference.mesh, reference.field, reference.streamlines)
    partition = build_partition(domain, reference.streamlines, reference.mesh.element_size,
                                cuts)
    timings["partition"] = time.perf_counter() - clock
    clock = time.perf_counter()
    counts = quantize(partition, size)
    timings["quantization"] = time.perf_counter() - clock
    clock = time.perf_counter()
    mesh = build_quad_mesh(domain, partition, counts, smoothing=smoothing)
    timings["quad_mesh"] = time.perf_counter() - clock
    clock = time.perf_counter()
    quality = mesh_quality(domain, mesh)
    timings["quality"] = time.perf_counter() - clock
    timings["total"] = sum(timings.values())
    return MeshResult(domain=domain, reference=reference, cuts=cuts, partition=partition,
                      counts=counts, mesh=mesh, quality=quality, size=size,
                      method="numerical", timings=timings)
