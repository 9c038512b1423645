"""The numerical reference for one domain: background mesh, cross field, singular points,
traced streamlines and the paper's labels, with the time each stage took.

The `field` command, the benchmarks and (later) dataset generation all need exactly this
bundle, so it is assembled in one place.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..input.domain import Domain
from ..input.pose import canonical_pose
from ..layout.tracing import trace_streamlines
from .background import BackgroundMesh, background_mesh
from .framefield import FrameField, compute_frame_field
from .labels import frame_labels


@dataclass(frozen=True)
class Reference:
    domain: Domain
    mesh: BackgroundMesh
    field: FrameField
    streamlines: tuple
    labels: np.ndarray | None  # (N, 2) int8; None when not asked for
    timings: dict  # stage -> seconds

    def to_json(self) -> dict:
        """The `field` output of DESIGN.md (plus where each streamline starts and ends)."""
        out = self.mesh.to_json()
        out["frames"] = self.field.frames.tolist()
        out["singularities"] = [{"xy": s.xy.tolist(), "valence": s.valence}
                                for s in self.field.singularities]
        out["streamlines"] = [line.points.tolist() for line in self.streamlines]
        out["streamline_ends"] = [{"start": line.start.to_json(), "end": line.end.to_json(),
                                   "capped": line.capped} for line in self.streamlines]
        out["labels"] = self.labels.tolist()
        out["healed"] = list(self.domain.healed)
        return out


def background_and_field(domain: Domain, nodes: int, timings: dict,
                         mesh: BackgroundMesh | None = None, strict: bool = True,
                         feature_size: float | None = None):
    """The stages every path shares: background mesh (unless given) and cross field.
    ``feature_size``: the quad mesh's element size (background_mesh)."""
    clock = time.perf_counter()
    if mesh is None:
        mesh = background_mesh(domain, nodes=nodes, strict=strict, feature_size=feature_size)
        timings["background"] = time.perf_counter() - clock
        clock = time.perf_counter()
    field = compute_frame_field(mesh, canonical_pose(domain))
    timings["field"] = time.perf_counter() - clock
    return mesh, field


def numerical_reference(domain: Domain, nodes: int = 2048,
                        mesh: BackgroundMesh | None = None, labels: bool = True) -> Reference:
    timings = {}
    mesh, field = background_and_field(domain, nodes, timings, mesh)
    clock = time.perf_counter()
    streamlines = trace_streamlines(domain, mesh, field)
    timings["tracing"] = time.perf_counter() - clock
    if labels:
        clock = time.perf_counter()
        labels = frame_labels(mesh, field.frames, streamlines)
        timings["labels"] = time.perf_counter() - clock
    else:
        labels = None
    timings["total"] = sum(timings.values())
    return Reference(domain, mesh, field, streamlines, labels, timings)
