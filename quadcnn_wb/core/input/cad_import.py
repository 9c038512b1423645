"""STEP/BREP/IGES input: the first planar face of the file, as a Domain in its plane.

Read through gmsh's OpenCASCADE importer so no FreeCAD is needed on the command line.
Lines and circular arcs stay exact; other curve kinds (B-splines, ellipses) become arc
splines (input.arc_splines, the rule FreeCAD's sketches and faces follow too).
"""

from __future__ import annotations

from pathlib import Path

import gmsh
import numpy as np

from ..gmsh_session import gmsh_session, silenced_stdio
from .arc_splines import DENSE, arc_spline
from .curves import Arc, Line, circumcenter, diameter_of
from .domain import DomainError, make_domain
from .healing import (
    HEAL_TOL,
    VERTEX_SNAP,
    onto_shared_vertices,
    piece_ends,
    reversed_piece,
    vertex_note,
)

EXACT_TOLERANCE = 1e-5  # a curve this close to a line or circle is taken as one (IGES
#                         writers store circles as B-splines that are off by ~1e-6)


def read_cad_face(path) -> object:
    path = Path(path)
    if not path.is_file():
        raise DomainError(f"{path}: no such file")
    if path.stat().st_size == 0:
        raise DomainError(f"{path}: the file is empty")
    with gmsh_session():
        try:
            with silenced_stdio():
                gmsh.model.occ.importShapes(str(path), highestDimOnly=False)
                gmsh.model.occ.synchronize()
        except Exception as exc:  # gmsh reports every reader failure as a bare Exception
            raise DomainError(f"{path}: cannot read as {path.suffix.lstrip('.').upper()}: "
                              f"{_first_line(exc)}") from None
        faces = [tag for _, tag in gmsh.model.getEntities(2)]
        if not faces:
            raise DomainError(f"{path}: the file holds no face")
        planar = [tag for tag in faces if gmsh.model.getType(2, tag) == "Plane"]
        if not planar:
            raise DomainError(f"{path}: no planar face (the first face is a "
                              f"{gmsh.model.getType(2, faces[0])} surface)")
        face = planar[0]
        frame = _plane_frame(face)
        _, curve_lists = gmsh.model.occ.getCurveLoops(face)
        size = _face_size(curve_lists, frame)
        read = [_loop_pieces([abs(int(tag)) for tag in tags], frame, size)
                for tags in curve_lists]
    read.sort(key=lambda loop: -_extent(loop[0]))  # holes lie inside: the outer loop is widest
    notes = [vertex_note(li, moved) for li, (_, moved) in enumerate(read) if moved]
    return make_domain([loop for loop, _ in read], units="mm", healed=tuple(notes))


def _loop_pieces(tags: list, frame, size: float) -> tuple[list, list]:
    """(one loop's pieces, chained; the curve-end moves onto shared vertices).  Each
    curve's ends go onto the vertices it shares with the loop's other curves (the file's
    own topology), from beyond HEAL_TOL up to VERTEX_SNAP of the part
    (healing.onto_shared_vertices)."""
    ends = [_end_vertices(tag, frame) for tag in tags]
    uses = {}
    for pair in ends:
        for vertex, _ in pair:
            uses[vertex] = uses.get(vertex, 0) + 1
    pieces, moved = [], []
    for tag, pair in zip(tags, ends):
        start, end = (xy if uses[vertex] > 1 else None for vertex, xy in pair)
        curve, moves = onto_shared_vertices(_curve_pieces(tag, frame, size), start, end,
                                            HEAL_TOL * size, VERTEX_SNAP * size)
        pieces.extend(curve)
        moved.extend(moves)
    return _chain(pieces), moved


def _end_vertices(tag: int, frame) -> tuple:
    """((vertex tag, its xy) at the curve's start, the same at its end): the curve's
    boundary points, matched to its ends by distance (one for a closed curve)."""
    lo, hi = gmsh.model.getParametrizationBounds(1, tag)
    first, last = _to_plane(frame, gmsh.model.getValue(1, tag, [float(lo[0]), float(hi[0])]))
    vertices = [(int(v), _to_plane(frame, gmsh.model.getValue(0, int(v), []))[0])
                for _, v in gmsh.model.getBoundary([(1, tag)], oriented=False)]
    if not vertices:
        return ((-tag, None), (-tag, None))
    at_start = min(vertices, key=lambda v: float(np.hypot(*(v[1] - first))))
    at_end = min(vertices, key=lambda v: float(np.hypot(*(v[1] - last))))
    return at_start, at_end


def _first_line(exc) -> str:
    text = str(exc).strip() or type(exc).__name__
    return text.splitlines()[0]


def _plane_frame(face: int):
    """Origin and in-plane axes; a face in the XY plane keeps its own x and y."""
    lo, hi = gmsh.model.getParametrizationBounds(2, face)
    uv = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2]
    normal = np.array(gmsh.model.getNormal(face, uv))
    normal /= np.linalg.norm(normal)
    point = np.array(gmsh.model.getValue(2, face, uv))
    if normal[2] < 0:
        normal = -normal
    x_axis = np.array([1.0, 0.0, 0.0])
    if abs(np.dot(x_axis, normal)) > 0.9:
        x_axis = np.array([0.0, 1.0, 0.0]) if abs(normal[2]) < 0.9 else x_axis
    x_axis = x_axis - np.dot(x_axis, normal) * normal
    if np.linalg.norm(x_axis) < 1e-9:
        x_axis = np.array([0.0, 1.0, 0.0]) - normal[1] * normal
    x_axis /= np.linalg.norm(x_axis)
    y_axis = np.cross(normal, x_axis)
    origin = np.dot(point, normal) * normal  # the plane's point nearest the global origin
    return origin, x_axis, y_axis


def _to_plane(frame, xyz) -> np.ndarray:
    origin, ex, ey = frame
    d = np.asarray(xyz, dtype=float).reshape(-1, 3) - origin
    return np.stack([d @ ex, d @ ey], axis=-1)


def _face_size(curve_lists, frame) -> float:
    """The face's diameter, from its curves sampled at fixed parameters: the pieces' scale
    must not hang on the part's pose (a bounding box's diagonal does, and a crank web
    turned by 37° got other pieces than in its own pose)."""
    points = []
    for tag in {abs(int(t)) for tags in curve_lists for t in tags}:
        lo, hi = gmsh.model.getParametrizationBounds(1, tag)
        us = np.linspace(float(lo[0]), float(hi[0]), 9)
        points.append(_to_plane(frame, gmsh.model.getValue(1, tag, list(us))))
    return diameter_of(np.vstack(points))


def _curve_pieces(tag: int, frame, part_size: float) -> list:
    """Exact line or arc when the curve is one (whatever OCC calls it), else an arc spline
    at the scale of the part."""
    lo, hi = gmsh.model.getParametrizationBounds(1, tag)
    u0, u1 = float(lo[0]), float(hi[0])

    def at(us):
        return _to_plane(frame, gmsh.model.getValue(1, tag, list(us)))

    probe = at(np.linspace(u0, u1, 33))
    span = diameter_of(probe)  # (a turned copy's too: not its bounding box)
    tol = EXACT_TOLERANCE * max(span, 1e-300)
    closed = np.hypot(*(probe[-1] - probe[0])) <= 1e-9 * max(span, 1e-300)
    chord = probe[-1] - probe[0]
    if not closed and np.max(np.abs(np.cross(chord, probe - probe[0]))) <= tol * np.hypot(*chord):
        return [Line(probe[0], probe[-1])]
    center = circumcenter(probe[0], probe[11], probe[22])
    if np.all(np.isfinite(center)):
        radii = np.hypot(*(probe - center).T)
        if np.ptp(radii) <= tol:
            if closed:
                return [Arc.circle(center, float(radii.mean()))]
            return [(probe[0], probe[16], probe[-1])]
    us = np.linspace(u0, u1, DENSE + 1)
    ex, ey = frame[1], frame[2]
    d = np.reshape(gmsh.model.getDerivative(1, tag, list(us)), (-1, 3))
    tangents = np.stack([d @ ex, d @ ey], axis=-1)
    return arc_spline(at(us), tangents, part_size)


def _chain(pieces: list) -> list:
    """Order and orient a loop's curves so each starts where the previous one ends: the
    nearest free end next (ties: the earlier piece, its start before its end), found for
    all pieces at once (a gear's loop has a thousand edges)."""
    if len(pieces) == 1:
        return pieces
    ends = np.array([np.concatenate([np.asarray(a, dtype=float), np.asarray(b, dtype=float)])
                     for a, b in map(piece_ends, pieces)])  # (n, 4): start xy, end xy
    remaining = list(range(1, len(pieces)))
    chain = [pieces[0]]
    while remaining:
        end = np.asarray(piece_ends(chain[-1])[1], dtype=float)
        candidates = ends[remaining].reshape(-1, 2)  # start, end of each remaining piece
        k = int(np.argmin(np.hypot(*(candidates - end).T)))
        piece = pieces[remaining.pop(k // 2)]
        chain.append(reversed_piece(piece) if k % 2 else piece)
    return chain


def _extent(loop) -> float:
    pts = []
    for piece in loop:
        if isinstance(piece, tuple):
            pts.extend(piece)
        elif isinstance(piece, Arc) and piece.is_full:
            pts.extend([piece.center - piece.radius, piece.center + piece.radius])
        else:
            pts.extend([piece.p0, piece.p1])
    return float(np.hypot(*np.ptp(np.array(pts), axis=0)))
