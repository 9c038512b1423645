"""Ray hints: where the separatrices run, marched coarsely, for the network to refine.

The paper's network sees only positions and frames and must discover, from the whole
shape, where the singular points are and which way their streamlines leave; on a CPU
budget that is the slow part of learning (a band one element wide, placed by global
geometry: the fast recipe reached IoU 0.39 on concave in 100 minutes).  The field already
knows the sources (singular points and concave corners) and their leaving directions —
reconstruction uses them anyway — so the "rays" recipe hands them to the network: every
separatrix is marched through the field with steps of a whole element (the field
interpolated in its triangle, as the tracer does), stopped at the boundary or within an
element of another source, one copy per connection kept; per node, the distance (in
element sizes) to the nearest ray heading along v1 and along v2, to the boundary, to
the nearest source, and the labels' crossed-triangle rule applied to the rays.

This is a coarse numerical tracer, and it is most of what the shipped models know: the
rule on the rays alone gives the reference labels on concave and 0.93 IoU on four_hole
(docs/learning.md, "hints alone").  What it lacks is the tracer's step and its exact
snapping and joining next to singular points.  All rays are marched together.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from ..core.layout.field_rules import SNAP, claim_separatrices, cross_angle

SOURCE_SNAP = SNAP  # a ray this close (in element sizes) to another source ends on it
CLIP = 4.0  # distances beyond this many element sizes all read as "far"
FEATURES = ("ray distance v1", "ray distance v2", "boundary distance", "source distance",
            "ray label v1", "ray label v2")
PAIRS = ((0, 1), (4, 5))  # hint columns that belong to v1 and v2: they trade places with them
RAY_ENCODING = ("rays: distance / h to the nearest coarse separatrix ray heading along v1, "
                "along v2, distance to the boundary / h, to the nearest source / h; each "
                f"clipped at {CLIP} and divided by it; then the label rule applied to the "
                "rays (0/1 for v1, v2)")


@dataclass(frozen=True)
class Rays:
    starts: np.ndarray  # (R, 2)
    directions: np.ndarray  # (R, 2) unit
    sources: np.ndarray  # (S, 2) singular points and source corners
    owner: np.ndarray  # (R,) the source each ray leaves


def field_rays(field) -> Rays:
    """Every separatrix of the field's singular points and source corners as a ray."""
    starts, dirs, points, owner = [], [], [], []
    for s, src in enumerate((*field.singularities, *field.corner_sources)):
        points.append(src.xy)
        for d in src.directions:
            starts.append(src.xy)
            dirs.append(d)
            owner.append(s)
    return Rays(np.array(starts, float).reshape(-1, 2), np.array(dirs, float).reshape(-1, 2),
                np.array(points, float).reshape(-1, 2), np.array(owner, dtype=np.int64))


def boundary_edges(triangles: np.ndarray) -> np.ndarray:
    """(E, 2) node pairs of the edges that belong to one triangle only."""
    edges = np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]],
                                    triangles[:, [2, 0]]]), axis=1).astype(np.int64)
    base = int(edges.max()) + 1
    keys, counts = np.unique(edges[:, 0] * base + edges[:, 1], return_counts=True)
    single = keys[counts == 1]  # one integer per edge: a 1-D unique, not a row-wise one
    return np.column_stack([single // base, single % base])


def bent_rays(rays: Rays, nodes: np.ndarray, triangles: np.ndarray, theta: np.ndarray,
              h: float, step: float = 1.0) -> tuple[list, np.ndarray]:
    """Each ray marched along the field (midpoint steps of `step`·h, the cross arm closest
    to the heading, the field interpolated in the triangle holding the point), stopped
    where it crosses the boundary or comes within SOURCE_SNAP·h of another source.

    A coarse hint, not a streamline: steps of a whole element, no exact snapping, all
    rays marched together.  Returns one (M, 2) polyline per ray and, per ray, the source
    it ended at (-1: the boundary).
    """
    edges = boundary_edges(triangles)
    return _march(rays, CrossField(nodes, triangles, theta), nodes, edges,
                  cKDTree(nodes[np.unique(edges)]), h, step)


def _march(rays, field, nodes, edges, boundary_tree, h, step=1.0):
    r = len(rays.starts)
    if not r:
        return [], np.zeros(0, dtype=np.int64)
    a, e = nodes[edges[:, 0]], nodes[edges[:, 1]] - nodes[edges[:, 0]]
    reach = step * h + float(np.hypot(*e.T).max())  # farther from the boundary: no crossing
    diag = float(np.hypot(*np.ptp(nodes, axis=0)))
    sources = rays.sources
    foreign = np.arange(len(sources))[None] != rays.owner[:, None]  # (R, S)
    pos, head = rays.starts.copy(), rays.directions.copy()
    alive = np.ones(r, bool)
    steps = np.zeros(r, int)
    ended_at = np.full(r, -1, dtype=np.int64)
    history = [pos.copy()]
    for count in range(1, int(np.ceil(1.5 * diag / (step * h))) + 1):
        idx = np.nonzero(alive)[0]
        if not len(idx):
            break
        mid = pos[idx] + 0.5 * step * h * field.arm(pos[idx], head[idx])
        new_head = field.arm(mid, head[idx])
        move = step * h * new_head
        frac = np.ones(len(idx))
        hit = np.zeros(len(idx), bool)
        close = boundary_tree.query(pos[idx])[0] < reach
        if close.any():  # first boundary crossing of pos -> pos + move, for those near it
            c = np.nonzero(close)[0]
            q = a[None] - pos[idx[c], None, :]
            m = move[c]
            denom = m[:, None, 0] * e[None, :, 1] - m[:, None, 1] * e[None, :, 0]
            with np.errstate(divide="ignore", invalid="ignore"):
                t = (q[..., 0] * e[None, :, 1] - q[..., 1] * e[None, :, 0]) / denom
                u = (q[..., 0] * m[:, None, 1] - q[..., 1] * m[:, None, 0]) / denom
            first = (count == 1)  # a corner's rays start on the boundary
            scale = np.hypot(*m.T)[:, None] * np.hypot(*e.T)[None, :]  # parallel: relative
            cross = (np.abs(denom) > 1e-12 * scale) & (t > (1.0 if first else 0.0)) & (t <= 1) \
                & (u >= 0) & (u <= 1)
            t_hit = np.where(cross, t, np.inf).min(axis=1)
            hit[c] = np.isfinite(t_hit)
            frac[c] = np.where(hit[c], t_hit, 1.0)
        new_pos = pos[idx] + frac[:, None] * move
        stop = hit
        if len(sources):
            gap = np.hypot(*(sources[None] - new_pos[:, None, :]).transpose(2, 0, 1))
            gap = np.where(foreign[idx], gap, np.inf)
            k = np.argmin(gap, axis=1)
            snap = (gap[np.arange(len(idx)), k] < SOURCE_SNAP * h) & ~stop
            new_pos[snap] = sources[k[snap]]
            ended_at[idx[snap]] = k[snap]
            stop = stop | snap
        pos[idx], head[idx] = new_pos, new_head
        steps[idx] = count
        alive[idx[stop]] = False
        history.append(pos.copy())
    track = np.stack(history)  # (steps + 1, R, 2); a stopped ray repeats its end
    return [track[: steps[i] + 1, i] for i in range(r)], ended_at


def one_ray_per_separatrix(rays: Rays, lines: list, ended_at: np.ndarray) -> list:
    """Indices of the rays to keep: a ray from source a that arrives at source b along
    b's separatrix k *is* that separatrix, so b's own ray along k goes (the tracer's
    rule, core.layout.field_rules.claim_separatrices: shorter connections claim their
    two separatrices first).  Two slightly different copies of one connection would
    widen its band of labels.  A ray's separatrix slot is the ray itself; the one it
    arrives along is the arriving source's ray closest to the direction it came from
    (a coarse ray is not compared with traced lines as the tracer does), and a ray
    whose end slot is taken is not joined to anything: it is a hint, not a partition
    edge."""
    length = np.array([np.hypot(*np.diff(p, axis=0).T).sum() for p in lines])
    arrival = np.full(len(lines), -1, dtype=np.int64)
    for i in np.nonzero(ended_at >= 0)[0]:
        b = ended_at[i]
        own = np.nonzero(rays.owner == b)[0]
        before = lines[i][-2] if len(lines[i]) > 1 else lines[i][-1]
        radial = before - rays.sources[b]
        arrival[i] = own[np.argmax(rays.directions[own] @ radial)] if len(own) else -1
    keep, _ = claim_separatrices(length, list(range(len(lines))),
                                 [int(a) if a >= 0 else None for a in arrival])
    return keep


class CrossField:
    """The cross field between the nodes: z = exp(4it) interpolated linearly in the
    triangle holding a point (field_rules.cross_angle, as the tracer does), found by
    walking from the triangle with the nearest centroid; points off the mesh take
    cross_angle_at.  For callers that have points, not a walk that knows its triangle."""

    def __init__(self, nodes, triangles, theta, walker=None, centroids=None, tree=None):
        from ..core.field.meshwalk import MeshWalker

        self.tree = tree if tree is not None else cKDTree(nodes)
        self.centroids = centroids if centroids is not None \
            else cKDTree(nodes[triangles].mean(axis=1))
        self.walker = walker if walker is not None else MeshWalker(nodes, triangles)
        self.triangles = triangles
        self.z = np.exp(4j * theta)

    @classmethod
    def on(cls, mesh, theta) -> CrossField:
        """On a BackgroundMesh, sharing its walker and trees (built once per mesh)."""
        return cls(mesh.nodes, mesh.triangles, theta, mesh.walker, mesh.centroid_tree,
                   mesh.node_tree)

    def angle(self, points):
        tri, bary, _ = self.walker.locate(self.centroids.query(points)[1], points)
        inside = tri >= 0
        out = np.empty(len(points))
        out[inside] = cross_angle(self.z, self.triangles, tri[inside], bary[inside])
        if not inside.all():
            out[~inside] = cross_angle_at(self.tree, self.z, points[~inside])
        return out

    def arm(self, points, heading):
        """The unit cross arm at each point closest to its heading.

        The rule of field_rules.nearest_arm, found by comparing the four arms instead of
        rounding the angle difference; the two can differ in the last bits, and the
        shipped models were trained on hints marched this way, so it stays."""
        arms = self.angle(points)[:, None] + np.arange(4)[None] * (np.pi / 2)
        dots = np.cos(arms) * heading[:, 0:1] + np.sin(arms) * heading[:, 1:2]
        best = arms[np.arange(len(points)), np.argmax(dots, axis=1)]
        return np.column_stack([np.cos(best), np.sin(best)])


def cross_angle_at(tree, z, points) -> np.ndarray:
    """One cross direction (radians) at each point: the inverse-distance mean of the 3
    nearest nodes' z = exp(4it), a quarter of its angle.  Cheap and frame-free (the
    average is taken in the quartic representation, where the four arms agree)."""
    dist, near = tree.query(points, k=3)
    w = 1.0 / np.maximum(dist, 1e-12)
    return np.angle((w * z[near]).sum(axis=1)) / 4.0


def ray_features(nodes: np.ndarray, triangles: np.ndarray, theta: np.ndarray, rays: Rays,
                 h: float, field: CrossField | None = None) -> np.ndarray:
    """(N, 6) float32 hints in [0, 1] (see FEATURES): distances, 0 meaning "on it", then
    the labels' own rule applied to the rays (1: a ray crosses a triangle of the node
    heading along that vector).  `field`: the cross field on these nodes, when the caller
    has one (CrossField.on a mesh shares its point location)."""
    from ..core.field.labels import crossed_labels, resample

    out = np.ones((len(nodes), len(FEATURES)))
    out[:, 4:] = 0.0
    field = field or CrossField(nodes, triangles, theta)
    edges = boundary_edges(triangles)
    boundary_tree = cKDTree(nodes[np.unique(edges)])
    tracks, ended_at = _march(rays, field, nodes, edges, boundary_tree, h)
    lines = [tracks[i] for i in one_ray_per_separatrix(rays, tracks, ended_at)
             if len(tracks[i]) > 1]
    if lines:
        pts, dirs = zip(*(resample(p, 0.25 * h) for p in lines))
        pts, dirs = np.concatenate(pts), np.concatenate(dirs)
        dist, near = cKDTree(pts).query(nodes, k=min(8, len(pts)),
                                        distance_upper_bound=CLIP * h)
        dist, near = dist.reshape(len(nodes), -1), near.reshape(len(nodes), -1)
        found = near < len(pts)
        d = dirs[np.where(found, near, 0)]  # (N, k, 2)
        c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
        with_v1 = np.abs(c * d[..., 0] + s * d[..., 1]) >= np.abs(c * d[..., 1] - s * d[..., 0])
        for column, aligned in ((0, with_v1), (1, ~with_v1)):
            best = np.where(found & aligned, dist, np.inf).min(axis=1)
            out[:, column] = np.minimum(best / h, CLIP) / CLIP
        frames = np.column_stack([np.cos(theta), np.sin(theta), -np.sin(theta), np.cos(theta)])
        out[:, 4:] = crossed_labels(field.walker, field.centroids, h, frames, lines)
    out[:, 2] = np.minimum(boundary_tree.query(nodes)[0] / h, CLIP) / CLIP
    if len(rays.sources):
        out[:, 3] = np.minimum(cKDTree(rays.sources).query(nodes)[0] / h, CLIP) / CLIP
    return out.astype(np.float32)


def hint_labels(x: np.ndarray) -> np.ndarray:
    """(N, 2) labels the hints alone give: the crossed-triangle rule on the rays (x with
    10 columns), or for older 8-column data a vector within one element size of a ray
    heading its way.  The baseline a "rays" model has to beat.  x: encoded."""
    if x.shape[1] >= 10:
        return np.rint(x[:, 8:10]).astype(np.uint8)
    return (x[:, 4:6] * CLIP < 1.0).astype(np.uint8)
