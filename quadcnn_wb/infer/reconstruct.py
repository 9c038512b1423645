"""Streamlines rebuilt from frame-vector labels, as the paper's §4 and Figure 8 describe.

From every separatrix direction of every singular point (and every concave-corner
direction), walk the label-1 vectors: among the m nearest labelled nodes ahead of the
current point (KD-tree), take the one whose vector makes the smallest angle with the
current direction, until a singular point or the boundary is reached.  The node chain is
then Laplace-smoothed, fitted by a smoothing spline and its ends snapped exactly onto the
singular point or the boundary curve.

Departures from the letter of §4, needed where streamlines lie a few elements apart
(four holes): a candidate lying off the line ahead pays for it (LATERAL) and after each
hop the walk moves across its heading onto the middle of the labelled band (hopping
between nodes drifts to one side, over to the next band); the first 0.75 element runs
straight along the separatrix (the crosses turn fast right at a singular point); and a
walk ends at a singular point only when it closes in on it along one of its separatrices
(as numerical tracing does), never because it passes beside it.

Trust but verify: a walk that stalls, turns back, jumps over a gap, leaves the domain,
runs far too long, or whose smoothed line runs across the field, is reported, and the
caller traces that separatrix numerically instead (`fallback`).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import splev, splprep
from scipy.spatial import cKDTree

from ..core.input.curves import winding_numbers
from ..core.layout.field_rules import (
    MAX_LENGTH,
    SNAP,
    SNAP_CANDIDATES,
    arrives_along,
    may_snap,
    one_line_per_separatrix,
    separatrix_sources,
    snap_targets,
)
from ..core.layout.streamlines import Endpoint, Streamline
from ..core.layout.tracing import integrate
from .rays import CrossField

NEIGHBOURS = 12  # m of the paper
MIN_STEP = 0.35  # a next node must lie this far ahead (element sizes)
MAX_STEP = 2.0  # and no farther than this (element sizes): a longer jump crosses a gap
MAX_TURN = math.radians(50)  # a step turning more than this counts as turning back
SMOOTHING_PASSES = 5
MAX_STRAY = 25.0  # degrees a rebuilt line may run across the field (over an element)
LEAVE = 0.75  # element sizes walked straight along the separatrix before the first hop
LATERAL = 0.3  # score penalty per element size a candidate lies off the heading's line
BAND_HALF_WIDTH = 1.0  # labelled nodes within this radius (element sizes) of a hop make its band


@dataclass(frozen=True)
class Walk:
    line: Streamline | None
    problem: str = ""  # why it could not be trusted (empty when fine)


class LabelledVectors:
    """The label-1 frame vectors, as points with a direction each, in a KD-tree."""

    def __init__(self, nodes: np.ndarray, frames: np.ndarray, labels: np.ndarray):
        pts, vecs = [], []
        for col in (0, 1):
            on = labels[:, col] == 1
            pts.append(nodes[on])
            vecs.append(frames[on, 2 * col: 2 * col + 2])
        self.points = np.concatenate(pts)
        self.vectors = np.concatenate(vecs)
        self.tree = cKDTree(self.points) if len(self.points) else None

    def __len__(self) -> int:
        return len(self.points)


def walk_labels(domain, mesh, field, vectors: LabelledVectors, sources, boundary_tree,
                boundary_ids, targets, target_kind) -> list:
    """One Walk per source (xy, direction, triangle, origin), all walked together.

    Each step, for every walk still under way: among the m nearest labelled vectors that
    lie ahead (at least MIN_STEP, at most MAX_STEP) and were not taken before, the one
    most parallel to the heading; then onto the band's middle, and the checks (turned
    back, too long, a source reached, the boundary reached, left the domain).  The walks
    are independent: batching them turns one tree query per step and walk into one per
    step, which is most of the cost.
    """
    h = mesh.element_size
    r = len(sources)
    if vectors.tree is None or not r:
        return [Walk(None, "no label-1 vectors") for _ in range(r)]
    start = np.array([np.asarray(s[0], dtype=float) for s in sources]).reshape(-1, 2)
    start_dir = np.array([np.asarray(s[1], dtype=float) for s in sources]).reshape(-1, 2)
    origins = [s[3] for s in sources]
    snap = _SnapTargets(targets, target_kind, field, origins)
    # The first stretch runs straight along the separatrix (as _finish draws it anyway):
    # right at a singular point the nodes' crosses turn fast, and the first hop's vector
    # may lie more than MAX_TURN off the separatrix although the walk is fine.
    current, heading = start + LEAVE * h * start_dir, start_dir.copy()
    paths = [[p.copy(), q.copy()] for p, q in zip(start, current)]
    travelled = np.full(r, LEAVE * h)
    used = np.zeros((r, len(vectors)), dtype=bool)
    walks: list = [None] * r
    active = np.arange(r)
    limit = MAX_LENGTH * domain.size
    k = min(NEIGHBOURS, len(vectors))

    def finish(i, points, end):
        walks[i] = Walk(_finish(field, points, origins[i], end, h, start_dir[i]))

    def boundary_end(i):
        end = _boundary_end(domain, current[i], boundary_tree, boundary_ids, mesh, h)
        if end is not None:
            finish(i, paths[i] + [end[1]], end[0])
        return end is not None

    for _ in range(int(limit / (MIN_STEP * h)) + 2):
        if not len(active):
            break
        dist, idx = vectors.tree.query(current[active], k=k)
        dist, idx = dist.reshape(len(active), k), idx.reshape(len(active), k)
        offsets = vectors.points[idx] - current[active, None, :]
        ahead = np.einsum("akc,ac->ak", offsets, heading[active])
        ok = (ahead >= MIN_STEP * h) & (dist <= MAX_STEP * h) & ~used[active[:, None], idx]
        vec = vectors.vectors[idx]  # (A, k, 2)
        along = np.einsum("akc,ac->ak", vec, heading[active])
        # A vector more than MAX_TURN off the heading belongs to a crossing band (the
        # lateral penalty below could otherwise prefer it to an aligned one off the line).
        straight = ok & (np.abs(along) >= math.cos(MAX_TURN))
        stalled = ~straight.any(axis=1)
        for i, turned in zip(active[stalled], ok[stalled].any(axis=1)):
            if not boundary_end(i):
                x, y = current[i]
                walks[i] = Walk(None, f"turned back at ({x:.6g}, {y:.6g})" if turned
                                else "stalled: no labelled vector ahead")
        rows, active = np.nonzero(~stalled)[0], active[~stalled]
        if not len(active):
            break
        side = np.abs(offsets[rows, :, 0] * heading[active, None, 1]
                      - offsets[rows, :, 1] * heading[active, None, 0])
        score = np.where(straight[rows], np.abs(along[rows]) - 0.02 * dist[rows] / h
                         - LATERAL * side / h, -np.inf)
        best = np.argmax(score, axis=1)
        chosen = idx[rows, best]
        cosine = along[rows, best]
        new_heading = vec[rows, best] * np.where(cosine >= 0, 1.0, -1.0)[:, None]
        used[active, chosen] = True
        target = vectors.points[chosen]
        travelled[active] += np.hypot(*(target - current[active]).T)
        previous = current[active].copy()
        current[active] = _band_centres(vectors, target, new_heading, h)
        heading[active] = new_heading
        for i in active:
            paths[i].append(current[i].copy())
        going = travelled[active] <= limit
        for i in active[~going]:
            walks[i] = Walk(None, "ran longer than any streamline should")
        hits = snap.reached(current[active], previous, travelled[active], active, h)
        for j, i in enumerate(active):
            if going[j] and hits[j] is not None:
                finish(i, paths[i][:-1] + [hits[j][1]], hits[j][0])
                going[j] = False
        gap = boundary_tree.query(current[active])[0]
        for j, i in enumerate(active):
            if going[j] and travelled[i] > h and gap[j] <= 0.5 * h and boundary_end(i):
                going[j] = False
        active = active[going]
        if len(active):
            outside = ~_inside_all(domain, current[active])
            for i in active[outside]:
                walks[i] = Walk(None, "left the domain")
            active = active[~outside]
    for i in active:
        walks[i] = Walk(None, "ran longer than any streamline should")
    return walks


class _SnapTargets:
    """Where walks may end (singular points, source corners), as arrays, so every walk
    under way is checked at once — by the rules of numerical tracing (core.layout.
    field_rules: may_snap, arrives_along): a walk snaps only while closing in on a point,
    not on its own start unless it went round, and on a singular point only when it
    arrives along one of that point's separatrices.  A hop is longer than a tracing
    step, so the distance is that of the hop's closest point, and the approach is seen
    from where the hop began."""

    def __init__(self, targets, target_kind, field, origins):
        self.xy = np.asarray(targets, dtype=float).reshape(-1, 2)
        self.kind = target_kind
        t = len(self.xy)
        self.own = np.array([[kind.same_place(o) for kind in target_kind] for o in origins],
                            dtype=bool).reshape(len(origins), t)
        self.corner = np.array([kind.kind == "corner" for kind in target_kind], dtype=bool)
        dirs = np.full((t, 6, 2), np.nan)
        for j, kind in enumerate(target_kind):
            if kind.kind == "singularity":
                d = field.singularities[kind.index].directions
                dirs[j, :len(d)] = d
        self.dirs = dirs
        self.singular = np.array([kind.kind == "singularity" for kind in target_kind],
                                 dtype=bool)

    def reached(self, points, previous, travelled, walks, h) -> list:
        """Per walk: (Endpoint, exact xy) of the source it ends at, or None."""
        out = [None] * len(points)
        if not len(self.xy):
            return out
        step = points - previous  # (A, 2)
        rel = self.xy[None] - previous[:, None, :]  # (A, T, 2)
        length2 = np.maximum((step * step).sum(axis=1), 1e-300)[:, None]
        along = np.clip(np.einsum("atc,ac->at", rel, step) / length2, 0.0, 1.0)
        d = np.hypot(*(rel - along[..., None] * step[:, None, :]).transpose(2, 0, 1))
        before = np.hypot(*rel.transpose(2, 0, 1))
        valid = may_snap(d, before, self.own[walks], self.corner[None], travelled[:, None], h)
        radial = -rel / np.maximum(before, 1e-300)[..., None]
        facing = np.nanmax(np.where(np.isnan(self.dirs[None, :, :, 0]), -np.inf,
                                    np.einsum("tsc,atc->ats", np.nan_to_num(self.dirs),
                                              radial)), axis=2)
        valid &= ~self.singular[None] | arrives_along(facing)
        order = np.argsort(d, axis=1)[:, :SNAP_CANDIDATES]  # the nearest, as tracing looks
        for a in range(len(points)):
            for j in order[a]:
                if d[a, j] > SNAP * h:
                    break
                if valid[a, j]:
                    out[a] = (self.kind[j], self.xy[j].copy())
                    break
        return out


def _stray(line, field_between, h) -> str:
    """Why a rebuilt line cannot be a streamline, or "": it must run along the field.

    Away from its ends (where the field turns fast around a singular point) a streamline
    is tangent to a cross arm everywhere; a walk that crossed over to a neighbouring
    band of labels, or cut a corner through a gap, runs across the field there.
    """
    pts = line.points
    seg = np.diff(pts, axis=0)
    length = np.hypot(*seg.T)
    s = np.concatenate([[0.0], np.cumsum(length)])
    inner = (s[:-1] > 1.5 * h) & (s[1:] < s[-1] - 1.5 * h) & (length > 0)
    if not inner.any():
        return ""
    mid = 0.5 * (pts[:-1] + pts[1:])[inner]
    t = field_between.angle(mid)
    angle = np.arctan2(seg[inner, 1], seg[inner, 0]) - t
    off = np.abs((angle + np.pi / 4) % (np.pi / 2) - np.pi / 4)  # to the nearest arm
    # over stretches of about an element: single wiggles of the spline do not count
    window = max(1, int(round(h / max(float(np.median(length[inner])), 1e-300))))
    smooth = np.convolve(off, np.ones(window) / window, mode="valid") if len(off) >= window \
        else off
    worst = float(np.degrees(smooth.max()))
    return f"runs {worst:.0f}° across the field" if worst > MAX_STRAY else ""


def _band_centres(vectors, points, headings, h):
    """Each point moved across its heading onto the middle of the labelled band there.

    The label-1 nodes are those of the triangles a streamline crosses, so they lie on
    both sides of it; hopping from node to node drifts to one side (the paper's choice
    looks at the vectors' angles, not at where the nodes lie), and in a dense layout
    the drift carries a walk over to a neighbouring streamline.
    """
    k = min(40, len(vectors))  # more than a band holds within one element
    dist, idx = vectors.tree.query(points, k=k, distance_upper_bound=BAND_HALF_WIDTH * h)
    dist, idx = dist.reshape(len(points), k), idx.reshape(len(points), k)
    found = idx < len(vectors)
    safe = np.where(found, idx, 0)
    aligned = found & (np.abs(np.einsum("akc,ac->ak", vectors.vectors[safe], headings))
                       > math.cos(math.radians(20)))
    normal = np.column_stack([-headings[:, 1], headings[:, 0]])
    offset = np.einsum("akc,ac->ak", vectors.points[safe] - points[:, None, :], normal)
    count = aligned.sum(axis=1)
    shift = np.where(count > 0, (offset * aligned).sum(axis=1) / np.maximum(count, 1), 0.0)
    return points + shift[:, None] * normal


def _inside_all(domain, points) -> np.ndarray:
    inside = winding_numbers(domain.loops[0], points) != 0
    for hole in domain.loops[1:]:
        inside &= winding_numbers(hole, points) == 0
    return inside


def _boundary_end(domain, p, boundary_tree, boundary_ids, mesh, h):
    """The exact boundary point near p when p is within half an element of the boundary."""
    dist, k = boundary_tree.query(p)
    if dist > 0.5 * h:
        return None
    node = int(boundary_ids[k])
    position = int(np.nonzero(mesh.boundary_nodes == node)[0][0])
    li = int(mesh.boundary_loop[position])
    best = None
    for si, curve in enumerate(domain.loops[li]):
        t = curve.project(p)
        q = curve.point(t)
        gap = float(np.hypot(*(q - p)))
        if best is None or gap < best[0]:
            best = (gap, si, t, q)
    _, si, t, q = best
    return Endpoint("boundary", -1, li, si, float(t)), q


def _finish(field, points, origin, end, h, direction) -> Streamline:
    """Laplace smoothing, a smoothing spline, and exact end points.

    Next to a singular point the labelled nodes scatter most, so the first and last
    stretch are replaced by the separatrix direction itself: the line leaves (and
    arrives) exactly as the field says, which keeps the block corners there clean.
    """
    pts = np.array(points, dtype=float)
    first, last = pts[0].copy(), pts[-1].copy()
    if origin.kind in ("singularity", "corner"):
        keep = np.hypot(*(pts - first).T) > 1.5 * h
        keep[0] = True
        pts = np.vstack([first, first + 0.75 * h * np.asarray(direction), pts[keep][1:]])
    sep = None
    if end.kind == "singularity":
        seps = field.singularities[end.index].directions
        back = pts[-2] - last if len(pts) > 1 else seps[0]
        sep = seps[int(np.argmax(seps @ (back / max(np.hypot(*back), 1e-300))))]
        keep = np.hypot(*(pts - last).T) > 1.5 * h
        keep[-1] = True
        pts = np.vstack([pts[keep][:-1], last + 0.75 * h * sep, last])
    for _ in range(SMOOTHING_PASSES):
        if len(pts) < 3:
            break
        pts[1:-1] = 0.25 * pts[:-2] + 0.5 * pts[1:-1] + 0.25 * pts[2:]
    if len(pts) >= 4:
        try:
            tck, _ = splprep(pts.T, s=len(pts) * (0.05 * h) ** 2, k=3)
            length = float(np.hypot(*np.diff(pts, axis=0).T).sum())
            n = max(4, int(length / (0.25 * h)))
            pts = np.array(splev(np.linspace(0, 1, n), tck)).T
        except (ValueError, TypeError):
            pass
    pts[0], pts[-1] = first, last
    # The smoothing bends the first and last stretch again; within half an element of a
    # singular point that can cross the point's next separatrix (a sliver block), so the
    # ends are put back on the separatrix exactly.
    if origin.kind in ("singularity", "corner") and len(pts) > 2:
        away = np.nonzero(np.hypot(*(pts - first).T) >= 0.75 * h)[0]  # the leading stretch
        if len(away):
            pts = np.vstack([first, first + 0.5 * h * np.asarray(direction), pts[away[0]:]])
    if sep is not None and len(pts) > 2:
        away = np.nonzero(np.hypot(*(pts - last).T) >= 0.75 * h)[0]  # the trailing one
        if len(away):
            pts = np.vstack([pts[:away[-1] + 1], last + 0.5 * h * sep, last])
    return Streamline(points=pts, start=origin, end=end, capped=False,
                      start_direction=None)


def reconstruct_streamlines(domain, mesh, field, labels) -> tuple[tuple, list]:
    """Streamlines from labels, one per separatrix; failed walks traced numerically.

    Returns (streamlines, problems): each problem is (source description, reason).
    """
    h = mesh.element_size
    walker = mesh.walker
    sources = separatrix_sources(mesh, field, walker, h)
    vectors = LabelledVectors(mesh.nodes, field.frames, labels)
    boundary_ids = mesh.boundary_nodes
    boundary_tree = cKDTree(mesh.nodes[boundary_ids])
    targets, target_kind = snap_targets(mesh, field)
    field_between = CrossField.on(mesh, field.theta)
    lines, failed, problems = [], [], []
    walks = walk_labels(domain, mesh, field, vectors, sources, boundary_tree, boundary_ids,
                        targets, target_kind)
    for source, walk in zip(sources, walks):
        xy, direction, _, origin = source
        problem = walk.problem if walk.line is None else _stray(walk.line, field_between, h)
        if problem:
            failed.append(source)
            problems.append((f"{origin.kind} {origin.index} branch {origin.branch}",
                             problem))
        else:
            lines.append(dataclasses.replace(walk.line, start_direction=direction))
    if failed:
        traced = integrate(domain, mesh, field, failed, walker)
        lines.extend(dataclasses.replace(line, fallback=True) for line in traced)
    return tuple(one_line_per_separatrix(lines, h)), problems
