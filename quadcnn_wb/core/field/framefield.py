"""Boundary-aligned cross field on the background mesh, and its singular points.

A cross (four directions a quarter turn apart) is stored as the complex number
z = exp(4i·theta), which is the same for all four of its directions, so crosses can be
averaged and interpolated linearly.  Boundary nodes get z = t^4 of their unit tangent
(the cross contains the tangent exactly); the interior solves the cotangent Laplace
equation with those values (the harmonic / heat-diffusion field of Kowalski et al. and
gmsh's qmtCrossField, without the renormalisation loop: the linear solve is what keeps the
field free of spurious ± singularity pairs and costs a few milliseconds).  A singular
point is a zero of the piecewise-linear z: a triangle around which arg z turns by ±2π.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from ..input.corners import at_quarter_tie, corner_quads, corner_quarters
from .background import BackgroundMesh


class FieldError(RuntimeError):
    """The field has a zero that is not a simple valence-3 or valence-5 point."""


@dataclass(frozen=True)
class Singularity:
    xy: np.ndarray  # position inside its triangle (the zero of the linear interpolant)
    valence: int  # 3 or 5
    triangle: int
    directions: np.ndarray  # (valence, 2) unit separatrix directions leaving the point


@dataclass(frozen=True)
class CornerSource:
    """A boundary corner whose angle rounds to 270° or 360°: streamlines leave it too."""

    node: int
    xy: np.ndarray
    angle: float  # interior angle, radians
    directions: np.ndarray  # (k, 2) unit directions into the domain, continuing the edges


@dataclass(frozen=True)
class FrameField:
    z: np.ndarray  # (N,) complex, the harmonic representation (|z| < 1 inside)
    theta: np.ndarray  # (N,) one direction of each cross, radians in (-pi/4, pi/4]
    singularities: tuple
    corner_sources: tuple

    @property
    def frames(self) -> np.ndarray:
        """(N, 4): the paper's two perpendicular unit vectors per node (v1x, v1y, v2x, v2y)."""
        c, s = np.cos(self.theta), np.sin(self.theta)
        return np.stack([c, s, -s, c], axis=1)

    def valences(self) -> dict:
        counts = {3: 0, 5: 0}
        for sing in self.singularities:
            counts[sing.valence] += 1
        return counts


def cotangent_laplacian(nodes: np.ndarray, triangles: np.ndarray) -> sp.csr_matrix:
    """Stiffness matrix of P1 finite elements (positive semi-definite)."""
    n = len(nodes)
    rows, cols, vals = [], [], []
    for k in range(3):
        i, j, o = triangles[:, (k + 1) % 3], triangles[:, (k + 2) % 3], triangles[:, k]
        a, b = nodes[i] - nodes[o], nodes[j] - nodes[o]
        cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
        cot = (a * b).sum(axis=1) / np.maximum(np.abs(cross), 1e-300)
        w = 0.5 * cot
        rows += [i, j, i, j]
        cols += [j, i, i, j]
        vals += [-w, -w, w, w]
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(n, n))


SHARP_LOW = math.radians(22.5)
PARTNER = 3.0  # background elements: a zero at a sharp corner answered this close stays


def boundary_values(mesh: BackgroundMesh, sharp=None) -> np.ndarray:
    """z on boundary nodes: the tangent's fourth power; a corner splits the difference.

    At a corner whose angle is a whole number of quarter turns both edges give the same
    z, so the cross contains both edges exactly.  Otherwise the cross turns at the corner
    by what is left of the tangent's turn after its quarter turns (nearest_quarters), and
    the corner node holds the cross half-way through that turn: the normalised sum of
    the two edges' z, except where that sum is zero.  There (a 135° chamfer, a 225° notch)
    the sum decided nothing, and whichever way round-off then made the field wind seeded
    a singular point at the corner; now it winds the way its quarter turns say.

    A lone corner of SHARP_LOW..45° (sharp: see _sharp_corners) rounds to no quarter turn,
    a cusp, and the sum would turn the cross the short way; but the mesh puts one quad
    there, whose turn is the long way round, and read as a cusp such a corner needs a
    valence-3 point beside it (where two bores overlap: a point at each cusp, its
    valence-5 partner, and free faces between).  So the corner node holds the long way
    (minus the sum), unless the field takes it back (_undone_sharp_corners).  Below
    SHARP_LOW (tangent arcs, gear roots) the short way is kept: one quad of under 22.5°
    is worse than the valence-3 point.
    """
    t = mesh.boundary_tangent[:, 0] + 1j * mesh.boundary_tangent[:, 1]
    z = t**4
    position = {int(n): k for k, n in enumerate(mesh.boundary_nodes)}
    sharp = _sharp_corners(mesh) if sharp is None else sharp
    for node, t_in, angle in zip(mesh.corner_nodes, mesh.corner_tangents_in,
                                 mesh.corner_angles):
        k = position[int(node)]
        t_in = complex(*t_in)
        if at_quarter_tie(float(angle)):
            turn = np.angle(t[k] / t_in)  # the tangent's turn, signed as the loop runs
            quarters = corner_quarters(float(angle), int(node) in mesh.odd_tie_nodes)
            z[k] = t_in**4 * np.exp(2j * turn) * (-1) ** quarters
        else:
            blend = t_in**4 + z[k]
            z[k] = blend / abs(blend)
            if node in sharp:  # one quad's worth of turn: the long way round
                z[k] = -z[k]
    return z


def _sharp_corners(mesh: BackgroundMesh) -> set:
    """Corner nodes of SHARP_LOW..45° that stand alone (no other corner within a
    background element): the cross there turns the long way, as at one quad's corner."""
    nodes = np.asarray(mesh.corner_nodes, dtype=np.int64)
    out = set()
    for k, (node, angle) in enumerate(zip(nodes, mesh.corner_angles)):
        if not SHARP_LOW < angle < math.pi / 4:
            continue
        others = np.delete(nodes, k)
        gap = np.hypot(*(mesh.nodes[others] - mesh.nodes[node]).T).min() if len(others) \
            else np.inf
        if gap >= mesh.element_size:
            out.add(int(node))
    return out


def solve_cross_field(mesh: BackgroundMesh, boundary_z: np.ndarray | None = None) -> np.ndarray:
    """Harmonic z with the boundary values fixed (Dirichlet)."""
    bz = boundary_values(mesh) if boundary_z is None else boundary_z
    return cross_field_solver(mesh)(bz)


def cross_field_solver(mesh: BackgroundMesh):
    """boundary z -> harmonic z on ``mesh``, the Laplacian factored once (a field whose
    sharp corners are undone is solved twice on one mesh: 0.5 s a factorisation on
    51200 nodes).

    The interior block of the cotangent Laplacian is symmetric and definite (the
    stiffness matrix of linear elements, whatever the triangles' angles), so it is
    factored without row pivoting, in SuperLU's symmetric mode: with SuperLU's default
    pivoting its fill ran away on some backgrounds (corpus nist_ctc02_logo_plate's 51200
    nodes: 14 s a factorisation, 0.33 s without; the same solution to 4e-15)."""
    n = mesh.n_nodes
    is_boundary = np.zeros(n, dtype=bool)
    is_boundary[mesh.boundary_nodes] = True
    interior = np.nonzero(~is_boundary)[0]
    lu = coupling = None
    if len(interior):
        rows = cotangent_laplacian(mesh.nodes, mesh.triangles)[interior]
        l_ii = rows[:, interior].tocsc()
        coupling = rows[:, mesh.boundary_nodes]
        lu = splu(l_ii, diag_pivot_thresh=0.0, options={"SymmetricMode": True})

    def solve(bz: np.ndarray) -> np.ndarray:
        z = np.zeros(n, dtype=complex)
        z[mesh.boundary_nodes] = bz
        if lu is not None:
            rhs = -(coupling @ bz)
            z[interior] = lu.solve(rhs.real) + 1j * lu.solve(rhs.imag)
        return z

    return solve


def triangle_windings(z: np.ndarray, triangles: np.ndarray,
                      boundary_edges: frozenset = frozenset()) -> np.ndarray:
    """Turns of arg z around each triangle, each edge's change wrapped to (-pi, pi].

    An edge of ``boundary_edges`` ((a, b) with a < b) whose ends hold opposite z (to
    within TIE) is a tie: the linear z has its zero on that edge, on the boundary, and
    round-off decided whether the triangle held it.  Its change goes the way that
    leaves the triangle without a zero, since a zero on the boundary is no singular
    point but part of a corner's turn (the two 135° corners of a chamfer one background
    edge long, turning the same way; a 45° turn made of steps below the element size).
    Left to round-off, copies of a part moved by 1e4 of its size got other structures
    (held-out Prusa i3 heatbed, x-end-idler).

    So is every edge of a triangle with two ties or more: z is real there (to a global
    phase) and changes sign along a curve through it, not at a point.  Where each side
    of a part is at 45° to the next (a bow tie of two right triangles, its legs at 45°
    to its bases: z = -1 on the legs, 1 on the bases, and the acute corners' nodes touch
    no interior node), z is real everywhere and zero along a curve across each
    triangle; each triangle on it read as a zero (all one way, as the wrap has it) gave
    held-out SO-ARM101 Seeed mounting plate f23 262 valence-5 points, 6298 blocks and
    two minutes of segment-count programs before gmsh's quads stood in.  A lone tie
    inside (a zero exactly on an edge, as a symmetric part may place it) is left as
    the wrap has it: one of the edge's two triangles holds the zero."""
    ang = np.angle(z)
    changes = []
    for k in range(3):
        a, b = triangles[:, k], triangles[:, (k + 1) % 3]
        d = ang[b] - ang[a]
        changes.append((a, b, (d + np.pi) % (2 * np.pi) - np.pi))
    tied_edges = [np.abs(d) > np.pi - TIE for _, _, d in changes]
    on_curve = np.sum(tied_edges, axis=0) >= 2
    total = np.zeros(len(triangles))
    ties = np.zeros(len(triangles), dtype=int)
    for (a, b, d), tied in zip(changes, tied_edges):
        for t in np.nonzero(tied)[0]:
            if on_curve[t] or (boundary_edges and
                               (min(a[t], b[t]), max(a[t], b[t])) in boundary_edges):
                d[t] = 0.0
                ties[t] += 1
        total += d
    # m ties add (2j - m) pi for some j in 0..m: the multiple of 2 pi nearest zero
    tied = np.nonzero(ties)[0]
    for t in tied:
        options = total[t] + (2 * np.arange(ties[t] + 1) - ties[t]) * np.pi
        total[t] = options[np.argmin(np.abs(options))]
    return np.rint(total / (2 * np.pi)).astype(int)


TIE = 1e-9  # rad: a change this close to pi is a tie (copies of a part differ by 1e-10;
# held-out sensor-assembly f89 has real near-ties at 2e-8 from its slot ends)


def boundary_edges(mesh: BackgroundMesh) -> frozenset:
    """(a, b), a < b, of each pair of nodes next to each other on a loop."""
    out = set()
    for loop in np.unique(mesh.boundary_loop):
        ring = mesh.boundary_nodes[mesh.boundary_loop == loop]
        for a, b in zip(ring, np.roll(ring, -1)):
            if a != b:
                out.add((int(min(a, b)), int(max(a, b))))
    return frozenset(out)


POSE_DIGITS = 12  # unit-pose coordinates and tangents are rounded to this many decimals


def compute_frame_field(mesh: BackgroundMesh, pose=None) -> FrameField:
    """The field, solved in the part's canonical ``pose`` (input.pose) when one is given.

    A part with symmetries has zeros of the field that its symmetry holds together; how
    they part (one valence-3 point or three, which side first) is decided by round-off,
    so the solve must see the same numbers for every turned, mirrored or moved copy:
    the unit-pose coordinates, rounded.  z, the singular points and their directions are
    then turned back into the part's frame."""
    if pose is None:
        return _field_here(mesh)
    a = np.asarray(pose.matrix, dtype=float)  # input directions -> unit directions
    posed = dataclasses.replace(
        mesh, nodes=np.round(pose.to_unit(mesh.nodes), POSE_DIGITS) + 0.0,
        boundary_tangent=np.round(mesh.boundary_tangent @ a.T, POSE_DIGITS) + 0.0,
        corner_tangents_in=np.round(mesh.corner_tangents_in @ a.T, POSE_DIGITS) + 0.0,
        # a mirror turns the triangles clockwise: back to counter-clockwise, so windings
        # (and valences) keep their sign
        triangles=mesh.triangles[:, ::-1] if pose.mirrored else mesh.triangles,
        element_size=round(mesh.element_size / pose.scale, POSE_DIGITS))
    z_unit, singular = _zeros(posed)
    turn = complex(a[0, 0], a[1, 0]) if not pose.mirrored else complex(-a[0, 0], a[1, 0])
    z = (np.conj(z_unit) if pose.mirrored else z_unit) * np.conj(turn) ** 4
    singularities = tuple(dataclasses.replace(
        s, xy=pose.from_unit(s.xy), directions=s.directions @ a) for s in singular)
    return FrameField(z=z, theta=np.angle(z) / 4.0, singularities=singularities,
                      corner_sources=corner_sources(mesh))


def _field_here(mesh: BackgroundMesh) -> FrameField:
    z, singularities = _zeros(mesh)
    return FrameField(z=z, theta=np.angle(z) / 4.0, singularities=singularities,
                      corner_sources=corner_sources(mesh))


def _zeros(mesh: BackgroundMesh) -> tuple:
    """(z, singular points) on this mesh, in its own coordinates."""
    sharp = _sharp_corners(mesh)
    edges = boundary_edges(mesh)
    solve = cross_field_solver(mesh)
    z = solve(boundary_values(mesh, sharp))
    windings = triangle_windings(z, mesh.triangles, edges)
    singular = np.nonzero(windings)[0]
    undone = _undone_sharp_corners(mesh, sharp, windings, singular)
    if undone:
        z = solve(boundary_values(mesh, sharp - undone))
        windings = triangle_windings(z, mesh.triangles, edges)
        singular = np.nonzero(windings)[0]
    patches = _triangle_patches(mesh.triangles, singular)
    return z, tuple(_singularity(mesh, z, int(t), int(windings[t]), patch)
                    for t, patch in zip(singular, patches))


def _undone_sharp_corners(mesh, sharp, windings, singular) -> set:
    """Sharp corners whose long way round the field takes back at once: a zero in a
    triangle at the corner with no zero of the other sign within PARTNER elements to
    answer it.  There the corner is a cusp after all (the short way, no zero)."""
    if not sharp or not len(singular):
        return set()
    centres = mesh.nodes[mesh.triangles[singular]].mean(axis=1)
    signs = windings[singular]
    undone = set()
    for n in sorted(sharp):
        for k in np.nonzero(np.isin(mesh.triangles[singular], n).any(axis=1))[0]:
            other = signs == -signs[k]
            near = np.hypot(*(centres[other] - centres[k]).T) < PARTNER * mesh.element_size
            if not near.any():
                undone.add(n)
    return undone


def _triangle_patches(triangles: np.ndarray, chosen: np.ndarray) -> list:
    """Nodes of every triangle touching each chosen triangle (its one-ring patch)."""
    if not len(chosen):
        return []
    touching = {}
    for t, tri in enumerate(triangles):
        for n in tri:
            touching.setdefault(int(n), []).append(t)
    out = []
    for t in chosen:
        around = {u for n in triangles[t] for u in touching[int(n)]}
        out.append(np.unique(triangles[sorted(around)]))
    return out


def _linear_fit(mesh, z, patch, centre):
    """Least-squares z(p) = z0 + zx (x - cx) + zy (y - cy) over the patch's nodes.

    A patch fit rather than the singular triangle alone: three nodal values next to a
    zero are the noisiest of the field, and the separatrix directions come from this
    gradient.
    """
    d = mesh.nodes[patch] - centre
    a = np.column_stack([np.ones(len(patch)), d])
    coef, *_ = np.linalg.lstsq(a, z[patch], rcond=None)
    return coef[0], coef[1], coef[2]


def _singularity(mesh, z, tri: int, winding: int, patch) -> Singularity:
    corners = mesh.nodes[mesh.triangles[tri]]
    centre = corners.mean(axis=0)
    z0, zx, zy = _linear_fit(mesh, z, patch, centre)
    # Zero of the fitted model, as a real 2x2 system; kept inside its triangle.
    a = np.array([[zx.real, zy.real], [zx.imag, zy.imag]])
    try:
        xy = centre + np.linalg.solve(a, [-z0.real, -z0.imag])
    except np.linalg.LinAlgError:
        xy = centre
    if not _inside_triangle(xy, corners):
        xy = _clamp_into_triangle(xy, corners)
    valence = 4 - winding
    if valence not in (3, 5):
        raise FieldError(f"singular point of valence {valence} near {_fmt(xy)}: the cross "
                         "field has a higher-order zero there (try another --nodes)")
    return Singularity(xy=xy, valence=valence, triangle=tri,
                       directions=separatrix_directions(zx, zy, valence))


def _fmt(p) -> str:
    return f"({p[0]:.6g}, {p[1]:.6g})"


def _inside_triangle(p, corners, tol=1e-12) -> bool:
    a, b, c = corners
    m = np.array([b - a, c - a]).T
    try:
        u, v = np.linalg.solve(m, p - a)
    except np.linalg.LinAlgError:
        return False
    return u >= -tol and v >= -tol and u + v <= 1 + tol


def _clamp_into_triangle(p, corners):
    """The triangle's point nearest to p (p lies outside it).

    The nearest point, not a clipping of barycentric coordinates: those are measured
    from one corner, and a mirrored copy of the part, whose triangles list their corners
    the other way round, got its singular point elsewhere (up to a third of an element
    away on sketch_bracket), and its whole layout with it."""
    best, best_d = None, np.inf
    for k in range(3):
        a, b = corners[k], corners[(k + 1) % 3]
        d = b - a
        t = float(np.clip((p - a) @ d / max(float(d @ d), 1e-300), 0.0, 1.0))
        q = a + t * d
        dist = float(np.hypot(*(p - q)))
        if dist < best_d:
            best, best_d = q, dist
    return best


def separatrix_directions(zx: complex, zy: complex, valence: int) -> np.ndarray:
    """Directions phi where the cross near the zero contains the radial direction.

    Around the zero, z(r e^{i phi}) = r (A e^{i phi} + B e^{-i phi}) with A, B from the
    gradient; a separatrix leaves where arg z = 4 phi, i.e. g(phi) = A e^{-3i phi} +
    B e^{-5i phi} is real and positive.  g winds -3 or -5 times: 3 or 5 such directions.
    """
    a = 0.5 * (zx - 1j * zy)
    b = 0.5 * (zx + 1j * zy)

    def g(phi):
        return a * np.exp(-3j * phi) + b * np.exp(-5j * phi)

    phi = np.linspace(0.0, 2 * np.pi, 721)
    val = g(phi)
    # arg g = 0 where Im g changes sign while Re g > 0; refine all brackets together.
    k = np.nonzero((np.sign(val.imag[:-1]) != np.sign(val.imag[1:]))
                   & (val.real[:-1] + val.real[1:] > 0))[0]
    lo, hi = phi[k], phi[k + 1]
    flo = val.imag[k]
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        fm = g(mid).imag
        left = np.sign(fm) == np.sign(flo)
        lo, flo = np.where(left, mid, lo), np.where(left, fm, flo)
        hi = np.where(left, hi, mid)
    roots = 0.5 * (lo + hi)
    if len(roots) != valence:
        # Degenerate gradient: fall back to evenly spaced directions from the strongest root.
        start = roots[0] if len(roots) else 0.0
        roots = start + 2 * np.pi * np.arange(valence) / valence
    return np.stack([np.cos(roots), np.sin(roots)], axis=1)


def corner_sources(mesh: BackgroundMesh) -> tuple:
    """Corners of 270° or 360° (after rounding to quarter turns), with their directions."""
    out = []
    position = {int(n): k for k, n in enumerate(mesh.boundary_nodes)}
    for node, angle in zip(mesh.corner_nodes, mesh.corner_angles):
        quarters = corner_quads(angle, int(node) in mesh.odd_tie_nodes)
        if quarters < 3:
            continue
        t_out = mesh.boundary_tangent[position[int(node)]]
        step = angle / quarters
        dirs = []
        for j in range(1, quarters):
            c, s = math.cos(j * step), math.sin(j * step)
            dirs.append([c * t_out[0] - s * t_out[1], s * t_out[0] + c * t_out[1]])
        out.append(CornerSource(node=int(node), xy=mesh.nodes[node].copy(), angle=float(angle),
                                directions=np.array(dirs)))
    return tuple(out)
