"""The region to mesh: an outer loop and hole loops of exact curves, validated.

Everything downstream assumes what this module guarantees, so every way an input can be
wrong is refused here with a message that names the loop and segment at fault:
outer loop counter-clockwise, holes clockwise (the domain always lies to the left),
loops closed exactly, no curve meets another except where consecutive curves join,
every hole strictly inside the outer loop and outside the other holes, positive area.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .curves import Arc, Line, curve_bbox, diameter_of, loop_signed_area, winding_number
from .healing import HEAL_TOL, arcs_through_their_ends, drop_crumbs, merge_curves, report_gaps
from .intersections import Overlap, curve_intersections

CLOSE_TOL = 1e-9  # relative to the domain size: what counts as exact


class DomainError(ValueError):
    """Bad input geometry; the message says what is wrong and where."""


@dataclass(frozen=True)
class Domain:
    loops: tuple  # tuple of tuples of curves; loops[0] outer (CCW), the rest holes (CW)
    units: str = "mm"
    bbox_min: np.ndarray = field(default=None, compare=False)
    bbox_max: np.ndarray = field(default=None, compare=False)
    healed: tuple = field(default=(), compare=False)  # what the input healing changed

    @property
    def size(self) -> float:
        """Diagonal of the bounding box: the scale all tolerances are relative to."""
        return float(np.hypot(*(self.bbox_max - self.bbox_min)))

    @property
    def center(self) -> np.ndarray:
        return 0.5 * (self.bbox_min + self.bbox_max)

    @property
    def holes(self) -> int:
        return len(self.loops) - 1

    @property
    def area(self) -> float:
        return float(sum(loop_signed_area(loop) for loop in self.loops))

    @property
    def perimeter(self) -> float:
        return float(sum(c.length for loop in self.loops for c in loop))

    def curves(self):
        """(loop index, segment index, curve) for every boundary curve."""
        for li, loop in enumerate(self.loops):
            for si, curve in enumerate(loop):
                yield li, si, curve

    def to_json(self) -> dict:
        return {"units": self.units,
                "loops": [[c.to_json() for c in loop] for loop in self.loops]}


def domain_from_json(data) -> Domain:
    """Parse and validate a Domain JSON v1 object (already decoded)."""
    if not isinstance(data, dict):
        raise DomainError("domain JSON must be an object with a 'loops' list")
    units = data.get("units", "mm")
    if not isinstance(units, str):
        raise DomainError("'units' must be a string")
    loops = data.get("loops")
    if not isinstance(loops, list) or not loops:
        raise DomainError("domain JSON needs a non-empty 'loops' list (loop 0 is the outer "
                          "boundary, further loops are holes)")
    parsed = []
    for li, loop in enumerate(loops):
        if not isinstance(loop, list) or not loop:
            raise DomainError(f"loop {li}: must be a non-empty list of segments")
        parsed.append([_parse_segment(seg, li, si) for si, seg in enumerate(loop)])
    return make_domain(parsed, units)


def _where(li: int, si: int | None = None) -> str:
    return f"loop {li}" if si is None else f"loop {li}, segment {si}"


def _parse_point(value, where: str, what: str) -> np.ndarray:
    if (not isinstance(value, (list, tuple)) or len(value) != 2
            or not all(_is_number(v) for v in value)):
        raise DomainError(f"{where}: {what} must be a pair of numbers, got {value!r}")
    point = np.array([float(v) for v in value])
    if not np.all(np.isfinite(point)):
        raise DomainError(f"{where}: {what} has a non-finite coordinate {value!r}")
    return point


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _parse_segment(seg, li: int, si: int):
    where = _where(li, si)
    if not isinstance(seg, dict) or len(seg) != 1:
        raise DomainError(f"{where}: a segment is an object with one key: line, arc or circle")
    (kind, value), = seg.items()
    if kind == "line":
        if not isinstance(value, list) or len(value) != 2:
            raise DomainError(f"{where}: a line needs [[x0, y0], [x1, y1]]")
        return Line(*(_parse_point(p, where, name) for p, name in zip(value, ("start", "end"))))
    if kind == "arc":
        if not isinstance(value, list) or len(value) != 3:
            raise DomainError(f"{where}: an arc needs [[x0, y0], [xm, ym], [x1, y1]]")
        names = ("start", "middle point", "end")
        return tuple(_parse_point(p, where, name) for p, name in zip(value, names))
    if kind == "circle":
        if not isinstance(value, dict) or set(value) != {"center", "radius"}:
            raise DomainError(f"{where}: a circle needs {{\"center\": [cx, cy], \"radius\": r}}")
        center = _parse_point(value["center"], where, "center")
        radius = value["radius"]
        if not _is_number(radius) or not math.isfinite(radius):
            raise DomainError(f"{where}: circle radius must be a finite number, got {radius!r}")
        if radius <= 0:
            raise DomainError(f"{where}: circle radius must be positive, got {radius!r}")
        return Arc.circle(center, float(radius))
    raise DomainError(f"{where}: unknown segment kind {kind!r} (expected line, arc or circle)")


def make_domain(loops, units: str = "mm", healed: tuple = ()) -> Domain:
    """Validate loops of curves and return the oriented Domain.

    Arcs may be given as curves or as (start, middle, end) point triples; the latter are
    checked for collinearity here, where the domain size that sets the tolerance is known.
    What CAD kernels leave within HEAL_TOL of the part's size is healed first (see
    healing.py) and listed in ``Domain.healed``, after ``healed``: what the reader
    healed already (curve ends moved onto the vertices a CAD file says they share).
    """
    size = _raw_size(loops)
    eps = CLOSE_TOL * size
    heal = HEAL_TOL * size
    notes = list(healed)
    loops = drop_crumbs(loops, heal, notes)
    curves = [[_make_arc(c, li, si, eps) if isinstance(c, tuple) else c
               for si, c in enumerate(loop)] for li, loop in enumerate(loops)]
    for li, loop in enumerate(curves):
        _check_loop_shape(loop, li, eps, heal)
    report_gaps(curves, eps, notes)
    curves = [arcs_through_their_ends(merge_curves(_close_loop(loop), li, heal, notes), size)
              for li, loop in enumerate(curves)]
    for li, loop in enumerate(curves):
        _check_not_flat(loop, li, eps)
    _check_intersections(curves, eps, heal)
    oriented = []
    for li, loop in enumerate(curves):
        ccw = loop_signed_area(loop) > 0
        want_ccw = li == 0
        oriented.append(tuple(loop) if ccw == want_ccw else _reverse_loop(loop))
    _check_nesting(oriented)
    boxes = [curve_bbox(c) for loop in oriented for c in loop]
    domain = Domain(tuple(oriented), units, np.min([b[0] for b in boxes], axis=0),
                    np.max([b[1] for b in boxes], axis=0), tuple(notes))
    if domain.area <= 1e-12 * domain.size**2:
        raise DomainError("the domain has zero area")
    return domain


RAW_SAMPLES = 8  # points per curve for the raw size


def _raw_size(loops) -> float:
    """The largest distance across the raw curves, sampled at fixed parameters: the scale
    of the closing and healing tolerances.  Unlike a bounding box it is the same for a
    turned copy, so the copy gets the same curves merged (a bounding-box tolerance merged
    two arcs of crank_arm_web turned by 37° and not in its own pose)."""
    t = np.linspace(0.0, 1.0, RAW_SAMPLES + 1)
    pts = []
    for loop in loops:
        for c in loop:
            pts.extend(c if isinstance(c, tuple) else c.point(t))
    size = diameter_of(pts)
    if size == 0.0:
        raise DomainError("the domain has zero area (all its points coincide)")
    return size


def _make_arc(points, li: int, si: int, eps: float) -> Arc:
    p0, pm, p1 = points
    where = _where(li, si)
    chord = float(np.hypot(*(p1 - p0)))
    if chord <= eps:
        raise DomainError(f"{where}: arc start and end coincide (use a circle for a full loop)")
    if min(np.hypot(*(pm - p0)), np.hypot(*(pm - p1))) <= eps:
        raise DomainError(f"{where}: arc middle point coincides with an end point")
    # Height of the middle point above the chord, relative to the chord: 0 means a line.
    height = abs(float((p1 - p0)[0] * (pm - p0)[1] - (p1 - p0)[1] * (pm - p0)[0])) / chord
    if height <= 1e-9 * chord:
        raise DomainError(f"{where}: arc points are collinear (use a line)")
    return Arc.through(p0, pm, p1)


def _check_loop_shape(loop, li: int, eps: float, heal: float) -> None:
    full = [si for si, c in enumerate(loop) if isinstance(c, Arc) and c.is_full]
    if full and len(loop) > 1:
        raise DomainError(f"{_where(li, full[0])}: a circle must be a loop by itself")
    for si, c in enumerate(loop):
        nxt = loop[(si + 1) % len(loop)]
        gap = float(np.hypot(*(nxt.p0 - c.p1)))
        if gap > heal:
            if len(loop) == 1:
                raise DomainError(f"{_where(li)}: open loop, its only segment does not end "
                                  f"where it starts (gap {gap:.6g}, more than the healing "
                                  f"tolerance {heal:.3g})")
            raise DomainError(f"{_where(li)}: open loop, segment {si} ends at "
                              f"{_fmt(c.p1)} but segment {(si + 1) % len(loop)} starts at "
                              f"{_fmt(nxt.p0)} (gap {gap:.6g}, more than the healing "
                              f"tolerance {heal:.3g})")


def _fmt(p) -> str:
    return f"({p[0]:.9g}, {p[1]:.9g})"


def _close_loop(loop) -> list:
    """Make consecutive curves meet exactly (the gaps are already within tolerance)."""
    if len(loop) == 1:
        return list(loop)
    out = [loop[0]]
    for c in loop[1:]:
        out.append(c.with_start(out[-1].p1))
    first = out[0]
    if not np.array_equal(first.p0, out[-1].p1):
        out[0] = first.with_start(out[-1].p1)
    return out


def _check_not_flat(loop, li: int, eps: float) -> None:
    if any(isinstance(c, Arc) for c in loop):
        return
    pts = np.array([c.p0 for c in loop])
    centered = pts - pts.mean(axis=0)
    if np.linalg.svd(centered, compute_uv=False)[-1] <= eps:
        raise DomainError(f"{_where(li)}: zero area (all its points lie on one line)")


def _check_intersections(loops, eps: float, heal: float) -> None:
    """Curves meet only where consecutive ones join.  At a tangent joint (a fillet) a
    kernel's round-off lets the curves cross again within about sqrt(2 r tol) of it,
    so such a second meeting is allowed that close to the joint and no farther."""
    flat = [(li, si, c) for li, loop in enumerate(loops) for si, c in enumerate(loop)]
    boxes = np.array([np.concatenate(curve_bbox(c)) for _, _, c in flat])
    lo, hi = boxes[:, :2] - eps, boxes[:, 2:] + eps
    touching = np.all((lo[:, None, :] <= hi[None, :, :]) & (lo[None, :, :] <= hi[:, None, :]),
                      axis=2)
    for i, j in zip(*np.nonzero(np.triu(touching, k=1))):
        li, si, ci = flat[i]
        lj, sj, cj = flat[j]
        allowed = _shared_vertices(loops, li, si, lj, sj)
        try:
            points = curve_intersections(ci, cj, eps)
        except Overlap:
            raise DomainError(_pair_message(li, si, lj, sj, "overlap")) from None
        radius = max([c.radius for c in (ci, cj) if isinstance(c, Arc)], default=0.0)
        near = 10 * eps + math.sqrt(2.0 * heal * radius)
        for p in points:
            if all(np.hypot(*(p - v)) > near for v in allowed):
                if _crossing(ci, cj, p, eps):
                    raise DomainError(_pair_message(li, si, lj, sj, f"cross at {_fmt(p)}"))
                raise DomainError(_pair_message(li, si, lj, sj, f"meet at {_fmt(p)}",
                                                TOUCH) + ": the face pinches to no width there")


def _crossing(c1, c2, p, eps: float) -> bool:
    """Whether two curves that meet at p pass through each other there, rather than
    touch (an end of either on the other, or tangent curves: two holes of a real part
    that meet at one point, where the face between them has no width)."""
    for c in (c1, c2):
        if min(np.hypot(*(p - c.p0)), np.hypot(*(p - c.p1))) <= 10 * eps:
            return False
    t1, t2 = c1.tangent(c1.project(p)), c2.tangent(c2.project(p))
    return abs(float(t1[0] * t2[1] - t1[1] * t2[0])) > TANGENT_SINE


TANGENT_SINE = 1e-6  # curves meeting at a smaller angle (radians) touch, they do not cross


def _shared_vertices(loops, li, si, lj, sj) -> list:
    if li != lj:
        return []
    n = len(loops[li])
    out = []
    if (si + 1) % n == sj:
        out.append(loops[li][sj].p0)
    if (sj + 1) % n == si:
        out.append(loops[li][si].p0)
    return out


INTERSECT = ("intersect", "intersects")  # (loops ..., a loop ... itself)
TOUCH = ("touch", "touches")


def _pair_message(li, si, lj, sj, what: str, verbs: tuple = INTERSECT) -> str:
    if li == lj:
        return f"loop {li} {verbs[1]} itself: segments {si} and {sj} {what}"
    return (f"loops {li} and {lj} {verbs[0]}: loop {li} segment {si} and loop {lj} "
            f"segment {sj} {what}")


def _reverse_loop(loop) -> tuple:
    return tuple(c.reversed() for c in reversed(loop))


PROBE_PARAMS = (0.5, 0.3, 0.7)


def _inside(loop, hole) -> bool:
    """Whether the hole lies inside the loop (loops do not meet, so all of it does or
    none): the majority of three points of it.  One point can sit exactly on the chord
    of one of the loop's arcs (a hole centred on a boss's chord), where round-off alone
    decides its winding number."""
    votes = sum(winding_number(loop, hole[0].point(t)) != 0 for t in PROBE_PARAMS)
    return votes >= 2


def _check_nesting(loops) -> None:
    outer = loops[0]
    for hi, hole in enumerate(loops[1:], start=1):
        if not _inside(outer, hole):
            raise DomainError(f"loop {hi} (a hole) lies outside the outer loop 0; loop 0 must "
                              "be the outer boundary")
    for hi, hole in enumerate(loops[1:], start=1):
        for hj, other in enumerate(loops[1:], start=1):
            if hi != hj and _inside(other, hole):
                raise DomainError(f"loop {hi} (a hole) lies inside hole loop {hj}")
