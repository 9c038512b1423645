"""What a streamline is, wherever it comes from: a polyline and where its two ends lie.

Numerical tracing (tracing.py), the rebuild from network labels (infer/reconstruct.py),
the connecting cuts (cuts.py) and the partition all pass streamlines on, and the
partition tells its vertices apart by these endpoints alone (a singular point, a corner,
a place on the boundary, or a T-junction on another streamline), so the types live
apart from any one way of making them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Endpoint:
    kind: str  # "singularity", "corner", "boundary" or "streamline" (a T-junction)
    index: int = -1  # singularity index, background node of the corner, or streamline index
    loop: int = -1  # for corner and boundary ends: where on the boundary
    segment: int = -1
    param: float = -1.0
    branch: int = -1  # at a singular point: which of its separatrix directions

    def same_place(self, other) -> bool:
        return (self.kind, self.index) == (other.kind, other.index)

    @property
    def place(self) -> tuple:
        """(kind, index) of a singular point or corner, numbered alike in every pose of
        the part (the background's nodes and zeros); ("", -1) for any other end: what
        ties between lines are decided by."""
        return (self.kind, self.index) if self.kind in ("corner", "singularity") else ("", -1)

    def to_json(self) -> dict:
        out = {"kind": self.kind}
        if self.index >= 0:
            out["index"] = self.index
        if self.branch >= 0:
            out["branch"] = self.branch
        if self.loop >= 0:
            out.update(loop=self.loop, segment=self.segment, param=self.param)
        return out


@dataclass(frozen=True)
class Streamline:
    points: np.ndarray  # (M, 2) polyline from start to end
    start: Endpoint
    end: Endpoint
    capped: bool = False
    start_direction: np.ndarray = field(default=None, compare=False)
    fallback: bool = False  # traced numerically because the cnn reconstruction failed

    @property
    def length(self) -> float:
        return float(np.hypot(*np.diff(self.points, axis=0).T).sum())
