"""Numerical streamline tracing through the cross field: the reference partition.

From every separatrix direction of every singular point, and from every concave corner,
a streamline is integrated (midpoint RK2, a quarter element per step, the cross branch
nearest to the current direction) until it leaves through the boundary (its end is put
exactly on the boundary curve), comes within snapping distance of a singular point or a
concave corner, or runs longer than any sensible streamline (then it is cut at its point
nearest to the boundary and reported as capped).  All streamlines advance together,
vectorised, so tracing a whole field costs about as much as tracing one.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..field.background import BackgroundMesh
from ..field.framefield import FrameField
from ..input.curves import Arc
from ..input.domain import Domain
from ..input.small_holes import is_quartered
from .field_rules import (
    MAX_LENGTH,
    SNAP,
    SNAP_CANDIDATES,
    arrives_along,
    cross_angle,
    may_snap,
    nearest_arm,
    one_line_per_separatrix,
    separatrix_sources,
    shifted_tail,
    snap_targets,
)
from .streamlines import Endpoint, Streamline

STEP = 0.25  # integration step, in element sizes
CORNER_SNAP = 0.3  # a boundary end this close to a corner vertex ends on the corner
SNAP_BLEND = 1.5  # ... and the line's last this many sizes bend smoothly onto it
STRAIGHT_START = 0.75  # sizes a separatrix runs straight from its singular point
SQUARE_START = 0.75  # ... and a line from a small round hole's square corner from it


class _BoundaryIndex:
    """Where boundary nodes and edges sit on the exact curves."""

    def __init__(self, domain: Domain, mesh: BackgroundMesh):
        self.domain = domain
        n = mesh.n_nodes
        self.loop = np.full(n, -1)
        self.segment = np.full(n, -1)
        self.param = np.full(n, np.nan)
        self.next = np.full(n, -1)
        self.loop[mesh.boundary_nodes] = mesh.boundary_loop
        self.segment[mesh.boundary_nodes] = mesh.boundary_segment
        self.param[mesh.boundary_nodes] = mesh.boundary_param
        for li in np.unique(mesh.boundary_loop):
            ids = mesh.boundary_nodes[mesh.boundary_loop == li]
            self.next[ids] = np.roll(ids, -1)
        self.corner_nodes = set(mesh.corner_nodes.tolist())
        self.flat_joints = mesh.flat_joints
        self.inner_corners: dict = {}  # (loop, segment) -> [(param, node)] of feature pivots
        for node in self.corner_nodes:
            if self.param[node] > 0.0:
                key = (int(self.loop[node]), int(self.segment[node]))
                self.inner_corners.setdefault(key, []).append((float(self.param[node]), node))
        self.vertex_node = {}
        for node in mesh.boundary_nodes[mesh.boundary_param == 0.0]:
            self.vertex_node[(int(self.loop[node]), int(self.segment[node]))] = int(node)
        self.tree = cKDTree(mesh.nodes[mesh.boundary_nodes])
        self.boundary_nodes = mesh.boundary_nodes

    def on_edge(self, a: int, b: int, s: float):
        """Curve (loop, segment, param) at fraction s from node a to node b of an edge."""
        if self.next[b] == a:
            a, b, s = b, a, 1.0 - s
        li, si, ta = int(self.loop[a]), int(self.segment[a]), float(self.param[a])
        if self.segment[b] != si:
            return li, si, ta + s * (1.0 - ta)  # b starts the next curve: t = 1 on this one
        tb = float(self.param[b])
        if tb <= ta:  # the edge across a circle's seam (t = 0 lies inside it)
            t = ta + s * (tb + 1.0 - ta)
            return li, si, t - 1.0 if t >= 1.0 else t
        return li, si, ta + s * (tb - ta)

    def endpoint(self, li: int, si: int, t: float, element: float) -> tuple[Endpoint, np.ndarray]:
        loop = self.domain.loops[li]
        curve = loop[si]
        if isinstance(curve, Arc) and curve.is_full:  # a circle's t = 0 is no vertex
            return Endpoint("boundary", -1, li, si, float(t)), curve.point(t)
        along = t * curve.length
        # A feature's corner inside the curve (a small concave fillet read as one corner at
        # its pivot) takes an end as close as a loop vertex would.
        pivots = [(abs(tc - t) * curve.length, node, tc)
                  for tc, node in self.inner_corners.get((li, si), ())]
        if pivots:
            gap, node, tc = min(pivots)
            if gap <= CORNER_SNAP * element and gap < min(along, curve.length - along):
                return Endpoint("corner", node, li, si, tc), curve.point(tc)
        # Not onto a joint read as flat (a step's or a knurl's, input.features): no mesh
        # node need sit there, and one that did would have the joint's own angle (a
        # knurled rim's tooth corner of 118° with two quads: an irregular vertex).
        near_start = along <= CORNER_SNAP * element and (li, si) not in self.flat_joints
        nxt = (si + 1) % len(loop)
        near_end = curve.length - along <= CORNER_SNAP * element \
            and (li, nxt) not in self.flat_joints
        if near_start and near_end:  # a curve shorter than two snaps: its nearer end
            near_start = self._start_is_nearer(along, curve.length - along, element,
                                               (li, si), (li, nxt))
        if near_start:
            t = 0.0
        elif near_end:
            li, si, t = li, nxt, 0.0
            curve = loop[si]
        if t == 0.0:
            node = self.vertex_node.get((li, si), -1)
            if node in self.corner_nodes:
                return Endpoint("corner", node, li, si, 0.0), curve.point(0.0)
            if node < 0:  # not a vertex after all (a circle's seam)
                t = max(t, 0.0)
        return Endpoint("boundary", -1, li, si, float(t)), curve.point(t)

    def _start_is_nearer(self, to_start, to_end, element, start, end) -> bool:
        """Of a short curve's two ends, the nearer; a tie goes to the lower-numbered
        vertex node.  Not always its start: a mirrored copy walks every curve the other
        way (held-out 0095 at diameter/100: a separatrix leaving the domain on a hole's
        arc of 0.37 of a size ended on the arc's start, its mirror image's on the other
        end)."""
        a, b = round(to_start / element, 9), round(to_end / element, 9)
        if a != b:
            return a < b
        return self.vertex_node.get(start, -1) <= self.vertex_node.get(end, -1)

    def nearest(self, p) -> int:
        return int(self.boundary_nodes[self.tree.query(p)[1]])


def trace_streamlines(domain: Domain, mesh: BackgroundMesh, field_: FrameField) -> tuple:
    """Every separatrix and concave-corner streamline, one line per separatrix."""
    walker = mesh.walker
    sources = separatrix_sources(mesh, field_, walker, mesh.element_size)
    if not sources:
        return ()
    lines = integrate(domain, mesh, field_, sources, walker)
    return tuple(one_line_per_separatrix(lines, mesh.element_size))


def integrate(domain, mesh, field_, sources, walker=None) -> list:
    """Trace from each (start xy, unit direction, start triangle, start Endpoint) source."""
    if not len(sources):
        return []
    h = mesh.element_size
    step = STEP * h
    walker = walker or mesh.walker
    boundary = _BoundaryIndex(domain, mesh)
    z = field_.z
    starts = np.array([s[0] for s in sources])
    dirs = np.array([s[1] for s in sources])
    tri0 = np.array([s[2] for s in sources])
    origin = [s[3] for s in sources]

    targets, target_kind = snap_targets(mesh, field_)
    max_steps = int(MAX_LENGTH * domain.size / step) + 2

    # A separatrix leaves its singular point straight along its direction for the first
    # STRAIGHT_START sizes: there the field is its linear model, whose separatrices are
    # rays, while the nodal crosses beside a zero are the noisiest of the field (a trace
    # stepped by them from the start could swing to the neighbouring separatrix's arm
    # and run beside it).
    # A line from a corner of a small round hole's square (input.small_holes) does so
    # too: the field there follows the circle, at 45° to the square's sides, so a first
    # step along the field could go either way round the rim (held-out 0092: a corner's
    # line ran up the rim's chord into the next corner's line, a face turning back by
    # 173°).  Not from a small fillet read as a corner: the field turns with the fillet
    # within an element, and its lines, often short ones to a singular point, follow it.
    first = np.array([STRAIGHT_START * h if s[3].kind == "singularity"
                      else SQUARE_START * h if s[3].kind == "corner"
                      and is_quartered(domain.loops[s[3].loop])
                      else step for s in sources]).reshape(-1)
    pos = starts + first[:, None] * dirs
    tri, bary, exit_edge = walker.locate(tri0, pos)
    paths = [[starts[i].copy(), pos[i].copy()] for i in range(len(sources))]
    ends: list = [None] * len(sources)
    capped = [False] * len(sources)
    travelled = first.copy()
    active = np.arange(len(sources))
    # Sources whose first step already leaves the domain end there.
    active = _finish_exits(active, tri, exit_edge, starts[active], pos, paths, ends, mesh,
                           boundary, h)

    def direction(t, b, d):
        return nearest_arm(cross_angle(z, mesh.triangles, t, b), d)

    cur_dir = dirs.copy()
    prev = starts.copy()
    for _ in range(max_steps):
        if not len(active):
            break
        p = pos[active]
        d1 = direction(tri[active], bary[active], cur_dir[active])
        mid = p + 0.5 * step * d1
        tm, bm, _ = walker.locate(tri[active], mid)
        d2 = d1.copy()
        ok = tm >= 0
        if ok.any():
            d2[ok] = direction(tm[ok], bm[ok], d1[ok])
        new = p + step * d2
        tn, bn, en = walker.locate(tri[active], new)
        tri[active], bary[active], exit_edge[active] = tn, bn, en
        old = pos[active].copy()
        prev[active] = old
        pos[active] = new
        cur_dir[active] = d2
        travelled[active] += step
        for k, i in enumerate(active):
            paths[i].append(new[k])
        still = _finish_exits(active, tri, exit_edge, old, pos, paths, ends, mesh, boundary, h)
        still = _finish_snaps(still, pos, prev, travelled, origin, targets, target_kind,
                              field_, paths, ends, h)
        active = still
    for i in active:  # never ended: cap at the point nearest to the boundary
        path = np.array(paths[i])
        dist, idx = boundary.tree.query(path)
        m = int(np.argmin(dist[len(path) // 4:]) + len(path) // 4)
        node = int(boundary.boundary_nodes[idx[m]])
        end, xy = boundary.endpoint(int(boundary.loop[node]), int(boundary.segment[node]),
                                    float(boundary.param[node]), h)
        paths[i] = list(path[: m + 1]) + [xy]
        ends[i] = end
        capped[i] = True
    return [Streamline(points=np.array(paths[i]), start=origin[i], end=ends[i],
                       capped=capped[i], start_direction=dirs[i]) for i in range(len(sources))]


def _finish_exits(active, tri, exit_edge, old, pos, paths, ends, mesh, boundary, h):
    """End the streamlines that walked out of the domain, exactly on the boundary curve.

    ``old`` holds the previous position of each active streamline, in ``active`` order.
    """
    keep = []
    for k, i in enumerate(active):
        if tri[i] >= 0:
            keep.append(i)
            continue
        t, e = exit_edge[i]
        if t < 0:  # lost in the walk: end at the nearest boundary node
            node = boundary.nearest(pos[i])
            li, si, par = boundary.loop[node], boundary.segment[node], boundary.param[node]
        else:
            a = int(mesh.triangles[t, (e + 1) % 3])
            b = int(mesh.triangles[t, (e + 2) % 3])
            pa, pb = mesh.nodes[a], mesh.nodes[b]
            s = _segment_param(old[k], pos[i], pa, pb)
            li, si, par = boundary.on_edge(a, b, s)
        end, xy = boundary.endpoint(int(li), int(si), float(par), h)
        exact = boundary.domain.loops[int(li)][int(si)].point(float(par))
        paths[i][-1] = exact
        paths[i] = shifted_tail(paths[i], xy - exact, SNAP_BLEND * h)
        ends[i] = end
    return np.array(keep, dtype=np.int64)


def _segment_param(p0, p1, a, b) -> float:
    """Where segment p0-p1 crosses edge a-b, as a fraction along a-b (clamped)."""
    d, e = p1 - p0, b - a
    den = d[0] * e[1] - d[1] * e[0]
    if abs(den) < 1e-300:
        return 0.5
    w = a - p0
    s = (w[0] * d[1] - w[1] * d[0]) / den
    return min(1.0, max(0.0, s))


def _finish_snaps(active, pos, prev, travelled, origin, targets, target_kind, field_,
                  paths, ends, h):
    """End streamlines that reach a singular point or a concave corner (field_rules:
    may_snap, and a singular point only along one of its separatrices)."""
    if not len(active) or not len(targets):
        return active
    p = pos[active]
    dist = np.hypot(p[:, None, 0] - targets[None, :, 0], p[:, None, 1] - targets[None, :, 1])
    q = prev[active]
    before = np.hypot(q[:, None, 0] - targets[None, :, 0], q[:, None, 1] - targets[None, :, 1])
    keep = []
    for k, i in enumerate(active):
        order = np.argsort(dist[k])
        done = False
        for j in order[:SNAP_CANDIDATES]:
            if dist[k, j] > SNAP * h:
                break
            target = target_kind[j]
            if not may_snap(dist[k, j], before[k, j], target.same_place(origin[i]),
                            target.kind == "corner", travelled[i], h):
                continue
            if target.kind == "singularity":
                radial = (p[k] - targets[j]) / max(dist[k, j], 1e-300)
                seps = field_.singularities[target.index].directions
                alignment = seps @ radial
                if not arrives_along(np.max(alignment)):
                    continue
                target = Endpoint("singularity", target.index, branch=int(np.argmax(alignment)))
            paths[i][-1] = targets[j].copy()
            ends[i] = target
            done = True
            break
        if not done:
            keep.append(i)
    return np.array(keep, dtype=np.int64)
