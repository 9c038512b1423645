"""Streamlines rebuilt from frame-vector labels, as the paper's §4 and Figure 8 describe.

From every separatrix direction of every singular point (and every concave-corner
direction), walk the label-1 vectors: among the m nearest labelled nodes ahead of the
current point (KD-tree), take the one whose vector makes the smallest angle with the
current direction, until a singular point or the boundary is reached.  The node chain is
then Laplace-smoothed, fitted by a smoothing spline and its ends snapped exactly onto the
singular point or the boundary curve.

Trust but verify: a walk that stalls, turns back, leaves the domain or runs far too long
is reported, and the caller traces that separatrix numerically instead (`fallback`).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import splev, splprep
from scipy.spatial import cKDTree

from ..core.curves import winding_number
from ..core.tracing import MAX_LENGTH, SNAP, Endpoint, Streamline

NEIGHBOURS = 12  # m of the paper
MIN_STEP = 0.35  # a next node must lie this far ahead (element sizes)
MAX_TURN = math.radians(50)  # a step turning more than this counts as turning back
SMOOTHING_PASSES = 5


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
        ok = (ahead >= MIN_STEP * h) & np.array([i not in used for i in idx])
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
        heading = new_heading
        travelled += float(np.hypot(*step_vec))
        path.append(current.copy())
        if travelled > limit:
            return Walk(None, "ran longer than any streamline should")
        snapped = _snap(current, travelled, origin, targets, target_kind, h)
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


def _inside(domain, p) -> bool:
    return winding_number(domain.loops[0], p) != 0 and all(
        winding_number(hole, p) == 0 for hole in domain.loops[1:])


def _snap(p, travelled, origin, targets, target_kind, h):
    if not len(targets):
        return None
    d = np.hypot(*(targets - p).T)
    for j in np.argsort(d)[:3]:
        if d[j] > SNAP * h:
            break
        target = target_kind[j]
        if target.same_place(origin) and (target.kind == "corner" or travelled < 3 * SNAP * h):
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
    lines, failed, problems = [], [], []
    for source in sources:
        xy, direction, _, origin = source
        walk = walk_labels(domain, mesh, field, vectors, xy, direction, origin,
                           boundary_tree, boundary_ids, targets, target_kind)
        if walk.line is None:
            failed.append(source)
            problems.append((f"{origin.kind} {origin.index} branch {origin.branch}",
                             walk.problem))
        else:
            lines.append(dataclasses.replace(walk.line, start_direction=direction))
    if failed:
        traced = integrate(domain, mesh, field, failed, walker)
        lines.extend(dataclasses.replace(line, fallback=True) for line in traced)
    return tuple(_one_line_per_separatrix(lines, h)), problems
