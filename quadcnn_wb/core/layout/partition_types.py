"""The block partition's data: its edges, blocks and free faces, and its errors.

The partition (partition.py) makes them, the subdivision of odd faces (subdivide.py)
and segment counting (quantize.py) rework them, the mesh builder (mesh/quadmesh.py,
mesh/free_faces.py) fills them; kept apart from the building so that each of those
imports the data and not one another.  With them, the small helpers every stage that
checks a face uses: a face's outline and signed area, the even-odd point-in-polygon test
and how an error message names a point.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np


class FreeFaceError(RuntimeError):
    """A free face could not be filled; ``origins`` name its streamline edges, which a
    rebuild may dissolve (merging the face with its neighbours)."""

    def __init__(self, message, origins):
        super().__init__(message)
        self.origins = frozenset(origins)


class PartitionError(RuntimeError):
    """The streamlines do not cut the domain into four-sided blocks.

    ``outline`` (when known) is the offending face's boundary, ``corners`` its corner
    points, for pictures of what went wrong."""

    def __init__(self, message, outline=None, corners=None):
        super().__init__(message)
        self.outline = outline
        self.corners = corners


@dataclass(frozen=True)
class BoundaryPiece:
    """Exact stretch of one boundary curve: parameter t0 to t1 of loops[loop][segment]."""

    loop: int
    segment: int
    t0: float
    t1: float


@dataclass
class Edge:
    points: np.ndarray  # polyline from vertex a to vertex b
    a: int
    b: int
    pieces: tuple = ()  # BoundaryPiece stretches, in order, for boundary edges
    streamline: int = -1  # source streamline index for interior edges
    origin: tuple = ()  # (streamline, a, b) of the edge before any split: names it across rebuilds
    # A boundary edge's length along its exact curves (pieces); -1 for a streamline edge.
    # Its polyline's chords differ from it by up to 1e-5 of an element, and differently in
    # a turned or mirrored copy (where the samples fall on a circle): enough to reorder
    # near-equal arcs in the segment-count program (quantize.geometric_order).
    exact_length: float = -1.0

    @property
    def is_boundary(self) -> bool:
        return bool(self.pieces)

    @cached_property
    def length(self) -> float:
        """Asked of every edge many times per face walk; an edge's points never change
        (a split or a renumbering makes a new Edge), so it is measured once."""
        if self.exact_length >= 0.0:
            return self.exact_length
        return float(np.hypot(*np.diff(self.points, axis=0).T).sum())


def pieces_length(domain, pieces) -> float:
    """Length of exact boundary stretches (BoundaryPiece) along their curves."""
    return float(sum(domain.loops[p.loop][p.segment].length * abs(p.t1 - p.t0)
                     for p in pieces))


@dataclass(frozen=True)
class Block:
    corners: tuple  # four vertex ids, counter-clockwise
    sides: tuple  # four tuples of (edge id, forward) from corner k to corner k+1


@dataclass(frozen=True)
class FreeFace:
    """A face of the arrangement that is no four-sided block, and why."""

    halves: tuple  # (edge id, forward) around the face, the face on the left
    reason: str
    holes: tuple = ()  # rings of (edge id, forward) of the loops inside it

    @property
    def rings(self) -> tuple:
        return (self.halves,) + tuple(self.holes)


@dataclass
class Partition:
    vertices: np.ndarray  # (V, 2)
    edges: list
    blocks: list
    cuts: list  # extra polylines added so that every face is a disk
    singular: tuple = ()  # vertex ids of singular points: never merged with another anchor
    free_faces: list = field(default_factory=list)  # FreeFace: unstructured quads there
    # Boundary vertex ids where the boundary has a corner (a loop's corner, a feature's):
    # a boundary arc with no segments may not move one (quantize.py, collapse.py).
    fixed: tuple = ()

    def edge_points(self, e: int, forward: bool) -> np.ndarray:
        pts = self.edges[e].points
        return pts if forward else pts[::-1]


def free_blocks(partition: Partition, chosen, reason: str) -> Partition:
    """The partition with these blocks (indices) turned into free faces."""
    chosen = set(chosen)
    if not chosen:
        return partition
    kept = [b for k, b in enumerate(partition.blocks) if k not in chosen]
    freed = [FreeFace(tuple(h for side in partition.blocks[k].sides for h in side), reason)
             for k in sorted(chosen)]
    return replace(partition, blocks=kept, free_faces=list(partition.free_faces) + freed)


def halves_outline(edges, halves) -> np.ndarray:
    """The points round a face given as (edge id, forward) halves."""
    return np.vstack([edges[e].points if forward else edges[e].points[::-1]
                      for e, forward in halves])


def polygon_area(pts) -> float:
    """Signed (shoelace) area: positive counter-clockwise."""
    return 0.5 * float(np.sum(pts[:, 0] * np.roll(pts[:, 1], -1)
                              - np.roll(pts[:, 0], -1) * pts[:, 1]))


def signed_area(edges, halves) -> float:
    return polygon_area(halves_outline(edges, halves))


def block_area_share(partition: Partition, domain_area: float) -> float:
    """The share of the domain's area in blocks (what is not in free faces): the
    structured share the partition's mesh will have, near enough to rank partitions
    before meshing them."""
    # A face's outline runs counter-clockwise, its holes clockwise.
    free = sum(signed_area(partition.edges, ring)
               for face in partition.free_faces for ring in face.rings)
    return 1.0 - free / domain_area


def inside_polygon(polygon, p) -> bool:
    """Even-odd rule: p strictly inside the closed polygon (points on it: either way).

    Over all edges at once, each crossing computed as the loop over them did (a loop
    took 0.7 ms a call on a 200-point outline, 0.15 s of a small part's partition)."""
    x, y = p
    start = np.asarray(polygon, dtype=float)
    end = np.roll(start, -1, axis=0)
    x0, y0, x1, y1 = start[:, 0], start[:, 1], end[:, 0], end[:, 1]
    crossing = (y0 > y) != (y1 > y)  # y1 != y0 on these
    x0, y0, x1, y1 = x0[crossing], y0[crossing], x1[crossing], y1[crossing]
    return bool(np.count_nonzero(x < x0 + (y - y0) * (x1 - x0) / (y1 - y0)) % 2)


def fmt(p) -> str:
    """A point as error messages write it."""
    return f"({p[0]:.6g}, {p[1]:.6g})"
