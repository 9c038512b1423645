"""Streamlines rebuilt from frame-vector labels, as the paper's §4 and Figure 8 describe.

From every separatrix direction of every singular point (and every concave-corner
direction), walk the label-1 vectors: among the m nearest labelled nodes ahead of the
current point (KD-tree), take the one whose vector makes the smallest angle with the
current direction, until a singular point or the boundary is reached.  The node chain is
then Laplace-smoothed, fitted by a smoothing spline and its ends snapped exactly onto the
singular point or the boundary curve.

Two departures from the letter of §4, both needed where streamlines lie a few elements
apart (four holes): after each hop the walk moves across its heading onto the middle of
the labelled band (hopping between nodes drifts to one side, over to the next band), and
it ends at a singular point only when it closes in on it along one of its separatrices
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

from ..core.curves import winding_number
from ..core.tracing import MAX_LENGTH, SNAP, SNAP_ANGLE, Endpoint, Streamline

NEIGHBOURS = 12  # m of the paper
MIN_STEP = 0.35  # a next node must lie this far ahead (element sizes)
MAX_STEP = 2.0  # and no farther than this (element sizes): a longer jump crosses a gap
MAX_TURN = math.radians(50)  # a step turning more than this counts as turning back
SMOOTHING_PASSES = 5
MAX_STRAY = 20.0  # degrees a rebuilt line may run across the field (over an element)


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


def walk_labels(domain, mesh, field, vectors: LabelledVectors, start_xy, direction, origin,
                boundary_tree, boundary_ids, targets, target_kind) -> Walk:
    """One streamline from start_xy along direction over the labelled vectors."""
    h = mesh.element_size
    if vectors.tree is None:
        return Walk(None, "no label-1 vectors")
    path = [np.asarray(start_xy, dtype=float)]
    current, heading = path[0], np.asarray(direction, dtype=float)
    used = set()
    travelled, limit = 0.0, MAX_LENGTH * domain.size
    for _ in range(int(limit / (MIN_STEP * h)) + 2):
        k = min(NEIGHBOURS, len(vectors))
        dist, idx = vectors.tree.query(current, k=k)
        idx = np.atleast_1d(idx)
        offsets = vectors.points[idx] - current
        ahead = offsets @ heading
        ok = (ahead >= MIN_STEP * h) & (np.atleast_1d(dist) <= MAX_STEP * h) \
            & np.array([i not in used for i in idx])
        if not ok.any():
            end = _boundary_end(domain, current, boundary_tree, boundary_ids, mesh, h)
            if end is not None:
                return Walk(_finish(field, path + [end[1]], origin, end[0], h, direction))
            return Walk(None, "stalled: no labelled vector ahead")
        cand = idx[ok]
        vec = vectors.vectors[cand]
        cosine = np.abs(vec @ heading)
        best = int(np.argmax(cosine - 0.02 * (np.atleast_1d(dist)[ok] / h)))
        chosen = int(cand[best])
        step_vec = vectors.points[chosen] - current
        new_heading = vec[best] * (1.0 if vec[best] @ heading >= 0 else -1.0)
        if math.acos(min(1.0, abs(float(vec[best] @ heading)))) > MAX_TURN:
            return Walk(None, "turned back")
        used.add(chosen)
        current = vectors.points[chosen]
        current = _band_centre(vectors, current, new_heading, h)
        heading = new_heading
        travelled += float(np.hypot(*step_vec))
        path.append(current.copy())
        if travelled > limit:
            return Walk(None, "ran longer than any streamline should")
        snapped = _snap(current, path[-2], travelled, origin, targets, target_kind, field, h)
        if snapped is not None:
            return Walk(_finish(field, path[:-1] + [snapped[1]], origin, snapped[0], h,
                                    direction))
        if travelled > h:  # a corner source starts on the boundary itself
            end = _boundary_end(domain, current, boundary_tree, boundary_ids, mesh, h)
            if end is not None:
                return Walk(_finish(field, path + [end[1]], origin, end[0], h, direction))
        if not _inside(domain, current):
            return Walk(None, "left the domain")
    return Walk(None, "ran longer than any streamline should")


def _stray(line, node_tree, theta, h) -> str:
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
    dist, near = node_tree.query(mid, k=3)
    w = 1.0 / np.maximum(dist, 1e-12)
    t = np.angle((w * np.exp(4j * theta[near])).sum(axis=1)) / 4.0
    angle = np.arctan2(seg[inner, 1], seg[inner, 0]) - t
    off = np.abs((angle + np.pi / 4) % (np.pi / 2) - np.pi / 4)  # to the nearest arm
    # over stretches of about an element: single wiggles of the spline do not count
    window = max(1, int(round(h / max(float(np.median(length[inner])), 1e-300))))
    smooth = np.convolve(off, np.ones(window) / window, mode="valid") if len(off) >= window \
        else off
    worst = float(np.degrees(smooth.max()))
    return f"runs {worst:.0f}° across the field" if worst > MAX_STRAY else ""


def _band_centre(vectors, p, heading, h):
    """p moved across the heading onto the middle of the labelled band around it.

    The label-1 nodes are those of the triangles a streamline crosses, so they lie on
    both sides of it; hopping from node to node drifts to one side (the paper's choice
    looks at the vectors' angles, not at where the nodes lie), and in a dense layout
    the drift carries a walk over to a neighbouring streamline.
    """
    near = vectors.tree.query_ball_point(p, 1.0 * h)
    if not near:
        return p
    near = np.asarray(near)
    aligned = near[np.abs(vectors.vectors[near] @ heading) > math.cos(math.radians(20))]
    if not len(aligned):
        return p
    normal = np.array([-heading[1], heading[0]])
    shift = float(np.mean((vectors.points[aligned] - p) @ normal))
    return p + shift * normal


def _inside(domain, p) -> bool:
    return winding_number(domain.loops[0], p) != 0 and all(
        winding_number(hole, p) == 0 for hole in domain.loops[1:])


def _snap(p, prev, travelled, origin, targets, target_kind, field, h):
    """The source a walk ends at: as numerical tracing decides it (core.tracing), a walk
    snaps only while closing in on a point, and on a singular point only when it arrives
    along one of its separatrices — in a dense layout (four holes) a walk passing beside
    another singular point must not end there."""
    if not len(targets):
        return None
    step = p - prev
    along = np.clip((targets - prev) @ step / max(float(step @ step), 1e-300), 0.0, 1.0)
    d = np.hypot(*(targets - (prev + along[:, None] * step)).T)  # closest on the hop
    before = np.hypot(*(targets - prev).T)
    for j in np.argsort(d)[:3]:
        if d[j] > SNAP * h:
            break
        if d[j] >= before[j]:
            continue
        target = target_kind[j]
        if target.same_place(origin) and (target.kind == "corner" or travelled < 3 * SNAP * h):
            continue
        if target.kind == "singularity":
            radial = (prev - targets[j]) / max(before[j], 1e-300)
            if np.max(field.singularities[target.index].directions @ radial) < \
                    math.cos(SNAP_ANGLE):
                continue
        return target, targets[j].copy()
    return None


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
    return Streamline(points=pts, start=origin, end=end, capped=False,
                      start_direction=None)


def reconstruct_streamlines(domain, mesh, field, labels) -> tuple[tuple, list]:
    """Streamlines from labels, one per separatrix; failed walks traced numerically.

    Returns (streamlines, problems): each problem is (source description, reason).
    """
    from ..core.meshwalk import MeshWalker
    from ..core.tracing import _one_line_per_separatrix, _snap_targets, _sources, integrate

    h = mesh.element_size
    walker = MeshWalker(mesh.nodes, mesh.triangles)
    sources = _sources(mesh, field, walker, h)
    vectors = LabelledVectors(mesh.nodes, field.frames, labels)
    boundary_ids = mesh.boundary_nodes
    boundary_tree = cKDTree(mesh.nodes[boundary_ids])
    targets, target_kind = _snap_targets(mesh, field)
    node_tree = cKDTree(mesh.nodes)
    lines, failed, problems = [], [], []
    for source in sources:
        xy, direction, _, origin = source
        walk = walk_labels(domain, mesh, field, vectors, xy, direction, origin,
                           boundary_tree, boundary_ids, targets, target_kind)
        problem = walk.problem if walk.line is None else _stray(walk.line, node_tree,
                                                                  field.theta, h)
        if problem:
            failed.append(source)
            problems.append((f"{origin.kind} {origin.index} branch {origin.branch}",
                             problem))
        else:
            lines.append(dataclasses.replace(walk.line, start_direction=direction))
    if failed:
        traced = integrate(domain, mesh, field, failed, walker)
        lines.extend(dataclasses.replace(line, fallback=True) for line in traced)
    return tuple(_one_line_per_separatrix(lines, h)), problems
