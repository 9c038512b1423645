"""The frame the whole pipeline runs in, so that every turned, moved or rescaled copy of a
part is meshed from one and the same set of numbers and gets the same mesh, turned back.

input.pose chooses a centre, a scale and a direction from the geometry alone; the
background mesh and the field were already solved in that pose, but the tracing,
partition, segment counts and quad mesh ran in the input's own coordinates.  There a
turned copy's numbers differ from the original's in their last bits, every stage's
arithmetic rounds differently, and a trace that passes a vertex or another trace within
round-off could end elsewhere (held-out blend 0043: other traces at 37°).  Here the
domain itself is put in the pose, its coordinates rounded to FRAME_DIGITS, so copies
whose poses agree to well within that hand bit-identical numbers to every stage; the
result is mapped back at the end.  Full circles start at the frame's +x (their start is
no vertex, and the input's +x turns with the part).

The mirror stays out of this frame: a mirror reverses every loop, and with it the
numbering of curves the result's sets are named by.  A mirrored copy is meshed from the
mirror image of these numbers (a sign, exact in floating point); the background mesh and
the field read it in their own mirrored pose, and the layout's tie rules treat both
images alike.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .field.background import BackgroundMesh
from .field.framefield import FrameField
from .field.reference import Reference
from .input.curves import Arc, Line, curve_bbox
from .input.domain import Domain
from .input.pose import Pose, canonical_pose
from .layout.partition_types import Partition
from .layout.streamlines import Streamline

FRAME_DIGITS = 12  # frame coordinates are rounded to this many decimals (of the diameter):
# far below any tolerance of the pipeline (1e-9 of the part at the tightest), far above the
# last bits a turn or a rescaling (1e-16) leaves in the input; a move by 1e4 of the part's
# size leaves about 1e-12, so such a copy's numbers may still differ in a few places
SIZE_DIGITS = 12  # relative rounding of the element size in the frame


@dataclasses.dataclass(frozen=True)
class Frame:
    """The pose without its mirror (``pose.matrix`` = ``mirror`` @ ``layout.matrix``)."""

    layout: Pose
    mirror: np.ndarray  # diag(-1, 1) or the identity

    @property
    def turn(self) -> complex:
        """exp(i alpha), where the frame turns input directions by alpha."""
        m = self.layout.matrix
        return complex(m[0, 0], m[1, 0])


def frame_of(domain: Domain) -> Frame:
    pose = canonical_pose(domain)
    mirror = np.diag([-1.0, 1.0]) if pose.mirrored else np.eye(2)
    return Frame(Pose(center=pose.center, scale=pose.scale, matrix=mirror @ pose.matrix),
                 mirror)


def _rounded(p) -> np.ndarray:
    return np.round(np.asarray(p, dtype=float), FRAME_DIGITS) + 0.0  # + 0.0: no -0.0


def framed_domain(domain: Domain, frame: Frame) -> Domain:
    """The domain in the frame, rounded; its own canonical pose is the mirror alone."""
    pose = frame.layout
    loops = tuple(tuple(_framed_curve(c, pose) for c in loop) for loop in domain.loops)
    out = _domain(loops, domain)
    out.__dict__["_canonical_pose"] = Pose(center=np.zeros(2), scale=1.0, matrix=frame.mirror)
    return out


def same_frame(layout: Domain, framed: Domain, domain: Domain, frame: Frame) -> Domain:
    """The layout's domain (framed, small holes squared: the same circles, in quarters)
    keeps the framed domain's pose; gmsh is handed the part as the caller had it (its
    squared holes' quarters turned back), in its canonical pose, as before the frame:
    the frame's rounding could move a coordinate onto a tie of gmsh's own rounding
    (gmsh_geometry.UNIT_DIGITS), and gmsh's triangles, chaotic in their input, change.
    Always in the given part's pose, which the frame is: gmsh's nodes are then the
    frame's, to the bit, but for the mirror (a sign)."""
    source = domain
    if layout is not framed:
        layout.__dict__["_canonical_pose"] = framed.__dict__["_canonical_pose"]
        loops = tuple(given if square is kept else
                      tuple(_world_curve(c, frame.layout) for c in square)
                      for given, kept, square in zip(domain.loops, framed.loops, layout.loops))
        source = _domain(loops, domain)
    layout.__dict__["_gmsh_source"] = (source, canonical_pose(domain))
    return layout


def framed_size(size: float, frame: Frame) -> float:
    unit = size / frame.layout.scale
    return float(f"{unit:.{SIZE_DIGITS}g}")


def _framed_curve(curve, pose: Pose):
    if isinstance(curve, Line):
        return Line(_rounded(pose.to_unit(curve.p0)), _rounded(pose.to_unit(curve.p1)))
    center = _rounded(pose.to_unit(curve.center))
    radius = round(curve.radius / pose.scale, FRAME_DIGITS)
    if curve.is_full:
        return Arc.circle(center, radius, counter_clockwise=curve.sweep > 0)
    p0, p1 = _rounded(pose.to_unit(curve.p0)), _rounded(pose.to_unit(curve.p1))
    a0 = math.atan2(p0[1] - center[1], p0[0] - center[0])
    return Arc(center, radius, a0, curve.sweep, p0, p1)


def _world_curve(curve, pose: Pose):
    if isinstance(curve, Line):
        return Line(pose.from_unit(curve.p0), pose.from_unit(curve.p1))
    center, p0, p1 = (pose.from_unit(p) for p in (curve.center, curve.p0, curve.p1))
    a0 = math.atan2(p0[1] - center[1], p0[0] - center[0])
    return Arc(center, curve.radius * pose.scale, a0, curve.sweep, p0,
               p0.copy() if curve.is_full else p1)


def _domain(loops, like: Domain) -> Domain:
    boxes = [curve_bbox(c) for loop in loops for c in loop]
    return Domain(loops, like.units, np.min([b[0] for b in boxes], axis=0),
                  np.max([b[1] for b in boxes], axis=0), like.healed)


def world_domain(domain: Domain, frame: Frame) -> Domain:
    """A framed domain (the layout's, with its squared holes) back in the input's frame."""
    pose = frame.layout
    return _domain(tuple(tuple(_world_curve(c, pose) for c in loop) for loop in domain.loops),
                   domain)


def _directions(d, pose: Pose) -> np.ndarray:
    return np.asarray(d, dtype=float) @ pose.matrix


def world_background(mesh: BackgroundMesh, frame: Frame) -> BackgroundMesh:
    pose = frame.layout
    return dataclasses.replace(
        mesh, nodes=pose.from_unit(mesh.nodes),
        boundary_tangent=_directions(mesh.boundary_tangent, pose),
        corner_tangents_in=_directions(mesh.corner_tangents_in, pose),
        element_size=mesh.element_size * pose.scale)


def world_field(field: FrameField, frame: Frame) -> FrameField:
    pose = frame.layout
    z = field.z * np.conj(frame.turn) ** 4
    return FrameField(
        z=z, theta=np.angle(z) / 4.0,
        singularities=tuple(dataclasses.replace(
            s, xy=pose.from_unit(s.xy), directions=_directions(s.directions, pose))
            for s in field.singularities),
        corner_sources=tuple(dataclasses.replace(
            c, xy=pose.from_unit(c.xy), directions=_directions(c.directions, pose))
            for c in field.corner_sources))


def _moved_line(line, points, directions):
    if isinstance(line, Streamline):
        start = line.start_direction
        return dataclasses.replace(line, points=points(line.points),
                                   start_direction=None if start is None else directions(start))
    return points(line)


def world_line(line, frame: Frame):
    pose = frame.layout
    return _moved_line(line, pose.from_unit, lambda d: _directions(d, pose))


def framed_line(line, frame: Frame):
    """A line found in the input's frame (a learned reconstruction) in the layout frame."""
    pose = frame.layout
    return _moved_line(line, pose.to_unit, lambda d: np.asarray(d, float) @ pose.matrix.T)


def world_partition(partition: Partition, frame: Frame) -> Partition:
    pose = frame.layout
    edges = [dataclasses.replace(
        e, points=pose.from_unit(e.points),
        exact_length=e.exact_length * pose.scale if e.exact_length >= 0.0 else e.exact_length)
        for e in partition.edges]
    return dataclasses.replace(
        partition, vertices=pose.from_unit(partition.vertices), edges=edges,
        cuts=[world_line(c, frame) for c in partition.cuts])


def world_reference(reference: Reference, frame: Frame) -> Reference:
    return dataclasses.replace(
        reference, domain=world_domain(reference.domain, frame),
        mesh=world_background(reference.mesh, frame),
        field=world_field(reference.field, frame),
        streamlines=tuple(world_line(line, frame) for line in reference.streamlines))


def world_result(result, frame: Frame, domain: Domain, size: float):
    """pipeline.MeshResult found in the frame, in the input's frame: ``domain`` as given,
    ``size`` as asked for.  Quality figures are kept as found (scaled Jacobians and counts
    do not change under a similarity, and so are the same for every copy)."""
    pose = frame.layout
    result.reference = world_reference(result.reference, frame)
    result.cuts = [world_line(c, frame) for c in result.cuts]
    result.partition = world_partition(result.partition, frame)
    nodes = pose.from_unit(result.mesh.nodes)
    on = np.nonzero(result.mesh.boundary)[0]
    nodes[on] = on_exact_curves(domain, nodes[on])
    result.mesh = dataclasses.replace(result.mesh, nodes=nodes)
    result.domain, result.size = domain, size
    return result


VERTEX_SNAP = 1e-8  # a boundary node this near (of the part's diameter) a curve's end is it


def on_exact_curves(domain: Domain, points: np.ndarray) -> np.ndarray:
    """Boundary nodes turned back land within the frame's rounding of the input's curves;
    each is put on the nearest curve exactly, and onto a curve's end where it is one (a
    corner node is the input's vertex to the bit, as exports and loads expect)."""
    if not len(points):
        return points
    best = np.full(len(points), np.inf)
    out = points.copy()
    near = VERTEX_SNAP * canonical_pose(domain).scale
    for loop in domain.loops:
        for curve in loop:
            t = _parameters(curve, points)
            if not (isinstance(curve, Arc) and curve.is_full):
                t[t * curve.length <= near] = 0.0
                t[(1.0 - t) * curve.length <= near] = 1.0
            on = curve.point(t)
            gap = np.hypot(*(on - points).T)
            closer = gap < best
            best[closer], out[closer] = gap[closer], on[closer]
    return out


def _parameters(curve, points: np.ndarray) -> np.ndarray:
    """Curve.project for many points at once."""
    if isinstance(curve, Line):
        d = curve.p1 - curve.p0
        return np.clip((points - curve.p0) @ d / (d @ d), 0.0, 1.0)
    sign = 1.0 if curve.sweep > 0 else -1.0
    angle = np.arctan2(points[:, 1] - curve.center[1], points[:, 0] - curve.center[0])
    rel = np.mod((angle - curve.a0) * sign, 2.0 * math.pi)
    span = abs(curve.sweep)
    if curve.is_full:
        return rel / span
    beyond = np.where(rel - span < 2.0 * math.pi - rel, 1.0, 0.0)
    return np.where(rel <= span, rel / span, beyond)
