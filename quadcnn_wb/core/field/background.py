"""The gmsh triangular background mesh that carries the frame field (paper §2.1, Fig. 1a).

The network reads a fixed-size point cloud (N = 2048 in the paper), so the node count is
a target hit within a few percent for any shape; the uniform element size that gives it is
found from the Euler relation and corrected from gmsh's actual counts.  Meshing runs on a
copy scaled to unit size, so a 1 µm part and a 100 km part see the same gmsh tolerances.
Boundary nodes are then put back exactly on the true curves, each with its curve,
parameter and tangent, because the frame field is aligned with that tangent.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass

import gmsh
import numpy as np
from scipy.spatial import cKDTree

from ..gmsh_geometry import UNIT_DIGITS, build_geometry
from ..gmsh_session import gmsh_session
from ..input.corners import interior_angle, is_corner, odd_ties
from ..input.curves import Arc
from ..input.domain import Domain
from ..input.features import JOINT_TOL, boundary_features, loop_offsets, mean_tangents
from ..input.pose import KEY_DIGITS, canonical_pose, default_size

NODE_TOLERANCE = 0.05  # the result holds target * (1 ± this) nodes ...
NODE_SLACK = 10  # ... or target ± this many, whichever is wider: below a few hundred nodes
#                  whole edges gain a node at once and the count moves in steps of ~20
MAX_SIZE_ITERATIONS = 12
GMSH_ALGORITHM = 6  # Frontal-Delaunay: near-equilateral triangles, no smoothing needed
GMSH_DENSITY = 1.045  # gmsh's frontal meshes hold this many times the ideal node count


class BackgroundMeshError(RuntimeError):
    """gmsh could not produce a mesh close enough to the requested node count."""


@dataclass(frozen=True)
class BackgroundMesh:
    nodes: np.ndarray  # (N, 2) float
    triangles: np.ndarray  # (T, 3) int, counter-clockwise
    boundary_nodes: np.ndarray  # (B,) int, loop by loop, in the loop's direction
    boundary_loop: np.ndarray  # (B,) int, loop index of each boundary node
    boundary_segment: np.ndarray  # (B,) int, curve index within its loop
    boundary_param: np.ndarray  # (B,) float in [0, 1) along that curve
    boundary_tangent: np.ndarray  # (B, 2) unit tangent; domain on the left
    corner_nodes: np.ndarray  # (C,) int, loop vertices where the tangent turns
    corner_angles: np.ndarray  # (C,) interior angle in radians, in (0, 2*pi]
    corner_tangents_in: np.ndarray  # (C, 2) unit tangent of the curve arriving at the corner
    element_size: float
    # (loop, segment) of the loop vertices that are no corner at the mesh's scale: part of
    # a feature below the element size (input.features), read as part of a side.
    flat_joints: frozenset = frozenset()
    # (loop, segment, parameter, interior angle) of the corners features put inside a
    # curve (a small fillet's middle): vertices of the partition, as loop vertices are.
    feature_corners: frozenset = frozenset()
    # Corner nodes of ties (odd multiples of 45°) that take the odd count of quarter
    # turns (input.corners.odd_ties).
    odd_tie_nodes: frozenset = frozenset()

    @property
    def n_nodes(self) -> int:
        return len(self.nodes)

    # Point location on this mesh, built once: tracing, labels, cuts, the ray hints and
    # the reconstruction all walk the same triangles (a copy made with
    # dataclasses.replace, e.g. jittered nodes, builds its own).
    @functools.cached_property
    def walker(self):
        from .meshwalk import MeshWalker

        return MeshWalker(self.nodes, self.triangles)

    @functools.cached_property
    def centroid_tree(self) -> cKDTree:
        """KD-tree of the triangle centroids: where a walk to a far point starts."""
        return cKDTree(self.nodes[self.triangles].mean(axis=1))

    @functools.cached_property
    def node_tree(self) -> cKDTree:
        return cKDTree(self.nodes)

    def to_json(self) -> dict:
        """The `background` output of DESIGN.md."""
        return {
            "nodes": self.nodes.tolist(),
            "triangles": self.triangles.tolist(),
            "boundary_nodes": self.boundary_nodes.tolist(),
            "corners": [{"node": int(n), "angle_deg": float(np.degrees(a))}
                        for n, a in zip(self.corner_nodes, self.corner_angles)],
        }


def expected_nodes(area: float, perimeter: float, holes: int, h: float) -> float:
    """Node count of a near-equilateral triangulation with edge length h.

    Triangles ~ area / (sqrt(3)/4 h^2), boundary nodes ~ perimeter / h, and Euler's
    relation for a disk with holes gives nodes = 1 - holes + (triangles + boundary) / 2.
    """
    return 2.0 * area / (math.sqrt(3.0) * h * h) + perimeter / (2.0 * h) + 1 - holes


def size_for_nodes(area: float, perimeter: float, holes: int, target: int) -> float:
    a = 2.0 * area / math.sqrt(3.0)
    b = perimeter / 2.0
    c = 1 - holes - target
    inv_h = (-b + math.sqrt(b * b - 4 * a * c)) / (2 * a)
    return 1.0 / inv_h


class SizeSearch:
    """Element size for a node count: bracketing secant search in log space.

    The count falls with the size but in steps (a thin strip gains a whole row at once),
    so a plain proportional update can jump over the target forever; keeping the sizes
    known to give too many and too few nodes makes each step land between them.
    """

    def __init__(self, target: int, h: float):
        self.target, self.h = target, h
        self.too_fine: tuple[float, int] | None = None  # (h, count) with count > target
        self.too_coarse: tuple[float, int] | None = None
        self.steps = 0

    def update(self, count: int) -> bool:
        """Record the count of the current size; False when the search must stop."""
        self.steps += 1
        if self.steps >= MAX_SIZE_ITERATIONS:
            return False
        if count > self.target:
            self.too_fine = (self.h, count)
        else:
            self.too_coarse = (self.h, count)
        if self.too_fine and self.too_coarse:
            (h0, n0), (h1, n1) = self.too_fine, self.too_coarse
            if h1 / h0 < 1.0 + 1e-6 or n0 == n1:
                return False
            slope = math.log(n1 / n0) / math.log(h1 / h0)
            guess = math.exp(math.log(h0) + math.log(self.target / n0) / slope)
            # Stay well inside the bracket so a step-shaped count still narrows it.
            lo, hi = h0 * (h1 / h0) ** 0.1, h0 * (h1 / h0) ** 0.9
            self.h = min(hi, max(lo, guess))
        else:
            self.h *= (count / self.target) ** 0.5
        return True


LOOSE_TOLERANCE = 0.5  # what the mesher accepts when the exact count cannot be had
RUNAWAY = 8  # times the node count asked for: gmsh's sizes come from small features


def _closest_count(session, curve_tags, nodes, h, tolerance, extend) -> tuple:
    """((coords, triangles, curve nodes), size) of the mesh whose node count came
    closest to ``nodes`` in SizeSearch's steps from ``h``; ``extend``: gmsh's
    Mesh.MeshSizeExtendFromBoundary."""
    session.set("Mesh.MeshSizeExtendFromBoundary", extend)
    search = SizeSearch(nodes, h)
    best = None
    while True:
        session.set("Mesh.MeshSizeMin", search.h)
        session.set("Mesh.MeshSizeMax", search.h)
        gmsh.model.mesh.clear()
        gmsh.model.mesh.generate(2)
        raw = _read_mesh(curve_tags)
        count = len(raw[0])
        if best is None or abs(count - nodes) < abs(len(best[0][0]) - nodes):
            best = (raw, search.h)
        if abs(count - nodes) <= tolerance or not search.update(count):
            return best
        if extend and count > RUNAWAY * nodes:
            return best  # the boundary's sizes rule the interior: see background_mesh


def background_mesh(domain: Domain, nodes: int = 2048, threads: int = 1,
                    strict: bool = True, feature_size: float | None = None) -> BackgroundMesh:
    """Triangulate the domain with ``nodes`` nodes, within NODE_TOLERANCE or NODE_SLACK.

    ``feature_size``: the element size of the quad mesh to come (default: the part's
    default size); boundary features below it are read at that scale (input.features).

    strict=False (the meshing pipeline) takes the closest count within LOOSE_TOLERANCE
    when a part with features far below the element size jumps over the target: the
    quad mesh does not need the exact count, only the network input does.
    """
    if nodes < 8:
        raise ValueError(f"--nodes must be at least 8, got {nodes}")
    pose = canonical_pose(domain)
    size = default_size(domain) if feature_size is None else feature_size
    features = boundary_features(domain, size)
    # A concave feature's corner inside a curve gets a vertex there: the one node that
    # stands for it, the same in a mirrored copy (the nearest of two could not be).  A
    # wider slot's round end holds two.
    splits = {}
    for f in features:
        if f.angle is not None and f.pivot_param > 0.0:
            splits.setdefault((f.loop, f.pivot_segment), set()).add(f.pivot_param)
    splits = {key: tuple(sorted(params)) for key, params in splits.items()}
    # Rounded well above round-off (a moved or turned copy must ask gmsh for the same size).
    # gmsh sees the part as the caller had it, in its canonical pose (core.layout_frame)
    source, source_pose = domain.__dict__.get("_gmsh_source", (domain, pose))
    unit_area = round(source.area / source_pose.scale**2, KEY_DIGITS)
    unit_perimeter = round(source.perimeter / source_pose.scale, KEY_DIGITS)
    h = size_for_nodes(unit_area, unit_perimeter, domain.holes, nodes / GMSH_DENSITY)
    tolerance = max(NODE_TOLERANCE * nodes, NODE_SLACK)
    allowed = tolerance if strict else max(tolerance, LOOSE_TOLERANCE * nodes)
    with gmsh_session(threads) as session:
        curve_tags = build_geometry(source, source_pose, splits)
        for option, value in (("Mesh.Algorithm", GMSH_ALGORITHM),
                              ("Mesh.MeshSizeFromPoints", 0),
                              ("Mesh.MeshSizeFromCurvature", 0),
                              ("Mesh.Smoothing", 0), ("Mesh.Optimize", 0)):
            session.set(option, value)
        best = _closest_count(session, curve_tags, nodes, h, tolerance, extend=1)
        if abs(len(best[0][0]) - nodes) > allowed:
            # Small features spread all over the part (a plate with fifteen 3 mm holes
            # in a grid): the sizes gmsh extends from the boundary into the interior
            # are theirs everywhere, and the count jumps from 156 to 9000 nodes as the
            # size shrinks (a 6 x 6 grid of 2 mm holes: 300 or 45000, 18 s of tries
            # before RUNAWAY).  Sizes from the size alone reach the count.
            other = _closest_count(session, curve_tags, nodes, h, tolerance, extend=0)
            if abs(len(other[0][0]) - nodes) < abs(len(best[0][0]) - nodes):
                best = other
    (coords, triangles, curve_nodes), h = best
    if abs(len(coords) - nodes) > allowed:
        raise BackgroundMeshError(
            f"could not reach {nodes} nodes within {NODE_TOLERANCE:.0%} (best "
            f"{len(coords)}); the shape may have features far below the element size")
    coords = pose.from_unit(coords)
    mesh = _assemble(domain, coords, triangles, curve_nodes, h * pose.scale, pose.scale)
    return with_features(mesh, domain, features)


def _read_mesh(curve_tags: dict):
    """Compact node array, triangles and the nodes of every boundary curve."""
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    tri_tags = []
    for dim, tag in gmsh.model.getEntities(2):
        types, _, node_tags = gmsh.model.mesh.getElements(dim, tag)
        for etype, nt in zip(types, node_tags):
            if etype == 2:
                tri_tags.append(np.asarray(nt, dtype=np.int64).reshape(-1, 3))
    tri_tags = np.concatenate(tri_tags)
    used = np.unique(tri_tags)
    index = np.full(int(max(tags.max(), used.max())) + 1, -1, dtype=np.int64)
    index[used] = np.arange(len(used))
    position = np.full(index.shape, -1, dtype=np.int64)
    position[np.asarray(tags, dtype=np.int64)] = np.arange(len(tags))
    coords = xyz.reshape(-1, 3)[position[used], :2]
    triangles = index[tri_tags]
    curve_nodes = {}
    for tag, key in curve_tags.items():
        ntags, _, _ = gmsh.model.mesh.getNodes(1, tag, includeBoundary=True)
        ids = index[np.asarray(ntags, dtype=np.int64)]
        # A split curve's halves: one list (sorted along the curve later, shared end once).
        curve_nodes[key] = np.concatenate([curve_nodes[key], ids]) if key in curve_nodes \
            else ids
    return coords, triangles, curve_nodes


def _assemble(domain: Domain, coords, triangles, curve_nodes, h,
              diameter_of_pose: float) -> BackgroundMesh:
    coords = np.array(coords, dtype=float)
    boundary, loops_of, segs_of, params, tangents = [], [], [], [], []
    corner_nodes, corner_angles, corner_in = [], [], []
    ties, odd_nodes = odd_ties(domain), set()
    for li, loop in enumerate(domain.loops):
        for si, curve in enumerate(loop):
            ids = curve_nodes[(li, si)]
            t = np.array([curve.project(coords[i]) for i in ids])
            # gmsh saw coordinates rounded to UNIT_DIGITS: nodes that close to a vertex
            # are the vertex itself (the pose's round trip is not exact either).
            near = 100 * 10.0 ** -UNIT_DIGITS * diameter_of_pose / curve.length
            if isinstance(curve, Arc) and curve.is_full:
                t[t >= 1.0 - near] = 0.0
            else:
                t[t <= near] = 0.0
                t[t >= 1.0 - near] = 1.0
            order = np.argsort(t, kind="stable")
            ids, t = ids[order], t[order]
            if not (isinstance(curve, Arc) and curve.is_full):
                ids, t = ids[:-1], t[:-1]  # the end vertex starts the next curve
            ids, keep = np.unique(ids, return_index=True)
            ids, t = ids[np.argsort(keep)], t[np.sort(keep)]
            coords[ids] = curve.point(t) if len(ids) > 1 else curve.point(t)[:1]
            boundary.extend(ids)
            loops_of.extend([li] * len(ids))
            segs_of.extend([si] * len(ids))
            params.extend(t)
            along = np.atleast_2d(curve.tangent(t))
            angle = None  # a lone circle has no joint
            if len(loop) > 1 or not getattr(curve, "is_full", False):
                angle = interior_angle(loop[si - 1], curve)
                if not is_corner(angle) and len(t) and t[0] == 0.0:
                    along[0] = _joint_tangent(loop[si - 1], curve)
            tangents.extend(along)
            if angle is not None and is_corner(angle):
                corner_nodes.append(int(ids[0]))
                corner_angles.append(angle)
                corner_in.append(loop[si - 1].tangent(1.0))
                if (li, si) in ties:
                    odd_nodes.add(int(ids[0]))
    triangles = _counter_clockwise(coords, np.asarray(triangles, dtype=np.int64))
    return BackgroundMesh(
        nodes=coords, triangles=triangles, boundary_nodes=np.array(boundary, dtype=np.int64),
        boundary_loop=np.array(loops_of, dtype=np.int64),
        boundary_segment=np.array(segs_of, dtype=np.int64),
        boundary_param=np.array(params, dtype=float),
        boundary_tangent=np.array(tangents, dtype=float).reshape(-1, 2),
        corner_nodes=np.array(corner_nodes, dtype=np.int64),
        corner_angles=np.array(corner_angles, dtype=float),
        corner_tangents_in=np.array(corner_in, dtype=float).reshape(-1, 2),
        element_size=float(h), odd_tie_nodes=frozenset(odd_nodes))


def with_features(mesh: BackgroundMesh, domain: Domain, features) -> BackgroundMesh:
    """The mesh with its boundary read through ``features`` (input.features): a feature's
    joints are no corners, a concave one is one corner at its pivot (a boundary node),
    and over the stretch the boundary's tangent is the one arriving at it up to the
    pivot and the one leaving it from there, so the cross field turns as at one corner."""
    if not features:
        return mesh
    tangents = mesh.boundary_tangent.copy()
    at = {int(n): k for k, n in enumerate(mesh.boundary_nodes)}
    corners = {}  # boundary position -> (node, angle, tangent in)
    where = {}  # (loop, segment) of each loop vertex's corner -> boundary position
    for node, angle, t_in in zip(mesh.corner_nodes, mesh.corner_angles,
                                 mesh.corner_tangents_in):
        k = at[int(node)]
        corners[k] = (int(node), float(angle), t_in)
        where[(int(mesh.boundary_loop[k]), int(mesh.boundary_segment[k]))] = k
    # Arc length of every boundary node along its loop, once.
    offsets = [loop_offsets(loop) for loop in domain.loops]
    lengths = [np.array([c.length for c in loop]) for loop in domain.loops]
    along = np.array([offsets[li][si] + t * lengths[li][si] for li, si, t in
                      zip(mesh.boundary_loop, mesh.boundary_segment, mesh.boundary_param)])
    flat, inside_curves = set(), set()
    for feature in features:
        total = float(offsets[feature.loop][-1])
        on_loop = np.nonzero(mesh.boundary_loop == feature.loop)[0]
        for si in feature.joints:
            flat.add((feature.loop, si))
            corners.pop(where.get((feature.loop, si)), None)
        if feature.window:  # a wavy loop: flat all round, its mean tangent
            tangents[on_loop] = mean_tangents(domain.loops[feature.loop], along[on_loop],
                                              feature.window)
            continue
        segs = mesh.boundary_segment[on_loop]
        s = along[on_loop]
        pivot_s = feature.pivot
        if feature.angle is not None:
            mine = on_loop[segs == feature.pivot_segment]
            if len(mine):
                params = mesh.boundary_param[mine]
                k = int(mine[np.argmin(np.abs(params - feature.pivot_param))])
                pivot_s = float(along[k])
                corners[k] = (int(mesh.boundary_nodes[k]), float(feature.angle),
                              feature.tangent_in)
                if feature.pivot_param > 0.0:
                    inside_curves.add((feature.loop, feature.pivot_segment,
                                       float(mesh.boundary_param[k]), float(feature.angle)))
        into = (s - feature.start) % total  # arc length into the stretch
        pivot = (pivot_s - feature.start) % total
        tol = JOINT_TOL * total
        inside = into < feature.end - feature.start
        if feature.end == feature.start:  # a smooth joint: its node alone (either side of
            inside = np.minimum(into, total - into) <= tol  # the joint, as round-off has it)
        before = inside & (into < pivot - tol)
        after = inside & (into > pivot + tol)
        tangents[on_loop[before]] = feature.tangent_in
        tangents[on_loop[after]] = feature.tangent_out
        if feature.angle is None:  # a flat stretch's middle node: the mean tangent
            mean = feature.tangent_in + feature.tangent_out
            tangents[on_loop[inside & ~before & ~after]] = mean / np.hypot(*mean)
        else:  # the corner node: the tangent leaving it, as at any corner
            tangents[on_loop[inside & ~before & ~after]] = feature.tangent_out
    order = sorted(corners)
    return dataclasses.replace(
        mesh, boundary_tangent=tangents,
        corner_nodes=np.array([corners[k][0] for k in order], dtype=np.int64),
        corner_angles=np.array([corners[k][1] for k in order], dtype=float),
        corner_tangents_in=np.array([corners[k][2] for k in order],
                                    dtype=float).reshape(-1, 2),
        flat_joints=frozenset(flat), feature_corners=frozenset(inside_curves))


def _joint_tangent(before, after) -> np.ndarray:
    """The tangent at a joint that is no corner: the mean of the two curves' (which
    differ by under CORNER_MIN_TURN).  The leaving curve's alone depends on which way
    the loop runs: a mirrored copy of held-out sensor-assembly f164 had every such
    joint's tangent from the other curve, 3e-7 rad apart, and at diameter/100 its field
    had a pair of singular points more (51 blocks against 55)."""
    mean = np.asarray(before.tangent(1.0), float) + np.asarray(after.tangent(0.0), float)
    return mean / np.hypot(*mean)


def _counter_clockwise(coords, triangles):
    a, b, c = (coords[triangles[:, k]] for k in range(3))
    signed = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    flipped = triangles.copy()
    flipped[signed < 0] = flipped[signed < 0][:, [0, 2, 1]]
    return flipped
