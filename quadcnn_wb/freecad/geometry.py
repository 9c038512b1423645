"""FreeCAD geometry to a QuadCNN Domain and back: sketches and planar faces in any placement.

A sketch's closed wires become a face (holes nested by FreeCAD's bullseye face maker); a
face is taken as it is.  Coordinates go into the face's own plane (the sketch's placement
for sketches), so the mesher sees a 2D domain; results go back through the same placement.
Lines and circular arcs stay exact; B-splines, ellipses and other curves become arc
splines (core.input.arc_splines, the importer's rule too).
"""

from __future__ import annotations

import FreeCAD
import numpy as np
import Part

from ..core.input.arc_splines import DENSE, arc_spline
from ..core.input.curves import Arc, Line, diameter_of
from ..core.input.domain import DomainError, make_domain
from ..core.input.healing import (
    HEAL_TOL,
    VERTEX_SNAP,
    onto_shared_vertices,
    piece_ends,
    reversed_piece,
    vertex_note,
)


def source_shape_and_placement(source):
    """(planar face, its plane in the shape's coordinates, that plane in global coordinates).

    Shapes of features inside a Body (or any container) are in the container's
    coordinates; the global plane adds the container's placement, so results land where
    the user sees the source.
    """
    if isinstance(source, (tuple, list)):
        obj, sub = source
        face = obj.Shape.getElement(sub)
        plane = _plane_placement(face, obj.Label)
    elif source.TypeId.startswith("Sketcher::SketchObject"):
        obj, face, plane = source, _sketch_face(source), source.Placement
    else:
        obj = source
        if not source.Shape.Faces:
            raise DomainError(f"{source.Label}: has no face to mesh")
        face = source.Shape.Faces[0]
        plane = _plane_placement(face, source.Label)
    container = obj.getGlobalPlacement().multiply(obj.Placement.inverse())
    return face, plane, container.multiply(plane)


def _sketch_face(sketch):
    shape = sketch.Shape
    if shape.isNull() or not shape.Edges:
        raise DomainError(f"{sketch.Label}: the sketch is empty")
    wires = shape.Wires
    loose = len(shape.Edges) - sum(len(w.Edges) for w in wires)
    open_wires = [w for w in wires if not w.isClosed()]
    if open_wires or loose:
        raise DomainError(f"{sketch.Label}: the sketch has an open wire (every profile must "
                          "be closed)")
    try:
        face = Part.makeFace(wires, "Part::FaceMakerBullseye")
    except Exception as exc:
        raise DomainError(f"{sketch.Label}: its wires do not make a face "
                          f"({str(exc).strip() or type(exc).__name__})") from None
    if len(face.Faces) != 1:
        raise DomainError(f"{sketch.Label}: the sketch makes {len(face.Faces)} separate "
                          "regions; QuadCNN meshes one region (with holes)")
    return face.Faces[0]


def _plane_placement(face, label):
    surface = face.Surface
    if not isinstance(surface, Part.Plane):
        try:
            plane = face.findPlane()
        except Exception:
            plane = None
        if plane is None:
            raise DomainError(f"{label}: the face is not planar")
        surface = plane
    normal = surface.Axis
    if face.Orientation == "Reversed":
        normal = normal.negative()
    rotation = FreeCAD.Rotation(FreeCAD.Vector(0, 0, 1), normal)
    return FreeCAD.Placement(surface.Position, rotation)


def face_to_domain(face, placement, label="face", units="mm"):
    """Domain in the plane's local coordinates; checks the face lies in that plane."""
    inverse = placement.inverse()
    size = _size_in_plane(face, inverse)
    tol = max(1e-7 * size, 1e-12)

    def local(v):
        p = inverse.multVec(v)
        if abs(p.z) > 1e-6 * size:
            raise DomainError(f"{label}: the face is not planar")
        return (p.x, p.y)

    def local_direction(v):
        d = inverse.Rotation.multVec(v)
        return (d.x, d.y)

    loops, notes = [], []
    for wire in [face.OuterWire] + [w for w in face.Wires if not w.isSame(face.OuterWire)]:
        loop, moved = [], []
        uses = _vertex_uses(wire)
        for edge in wire.OrderedEdges:
            # The importer's rule: ends go onto the vertices the wire's edges share.
            start, end = (local(v.Point) if uses[v.hashCode()] > 1 else None
                          for v in _end_vertices(edge))
            pieces, moves = onto_shared_vertices(
                _edge_pieces(edge, local, local_direction, tol, size), start, end,
                HEAL_TOL * size, VERTEX_SNAP * size)
            loop.append(pieces)
            moved.extend(moves)
        if moved:
            notes.append(vertex_note(len(loops), moved))
        loops.append(_chain(loop))
    return make_domain(loops, units=units, healed=tuple(notes))


def _end_vertices(edge) -> tuple:
    """The edge's vertices at its start and at its end, matched by distance."""
    first = edge.valueAt(edge.FirstParameter)
    last = edge.valueAt(edge.LastParameter)
    return (min(edge.Vertexes, key=lambda v: (v.Point - first).Length),
            min(edge.Vertexes, key=lambda v: (v.Point - last).Length))


def _vertex_uses(wire) -> dict:
    """How many edge ends of the wire each topological vertex holds (by its hash, which
    like isSame ignores orientation), counted once per wire: asked per edge end, a
    thousand-edge gear took a million comparisons."""
    uses = {}
    for edge in wire.Edges:
        for v in edge.Vertexes:
            uses[v.hashCode()] = uses.get(v.hashCode(), 0) + 1
    return uses


def _size_in_plane(face, inverse) -> float:
    """The face's diameter in its plane, from its edges sampled at fixed parameters: the
    same for a sketch in any placement (the global bounding box's diagonal is not)."""
    points = []
    for edge in face.Edges:
        for u in np.linspace(edge.FirstParameter, edge.LastParameter, 9):
            p = inverse.multVec(edge.valueAt(float(u)))
            points.append((p.x, p.y))
    return diameter_of(points)


def _edge_pieces(edge, local, local_direction, tol, size):
    curve = edge.Curve
    first, last = edge.FirstParameter, edge.LastParameter
    start, end = local(edge.valueAt(first)), local(edge.valueAt(last))
    if isinstance(curve, (Part.Line, Part.LineSegment)):
        return [Line(np.array(start), np.array(end))]
    if isinstance(curve, Part.Circle):
        if edge.isClosed():
            c = local(curve.Center)
            return [Arc.circle(np.array(c), curve.Radius)]
        mid = local(edge.valueAt(0.5 * (first + last)))
        return [(np.array(start), np.array(mid), np.array(end))]
    us = np.linspace(first, last, DENSE + 1)
    points = np.array([local(edge.valueAt(u)) for u in us])
    if edge.isClosed() and np.hypot(*(points[0] - points[-1])) <= tol:
        points[-1] = points[0]
    tangents = np.array([local_direction(edge.derivative1At(u)) for u in us])
    return arc_spline(points, tangents, size)


def _chain(edges):
    """One wire's pieces, each edge's (in its parameter order) turned as a whole so that
    it starts where the previous edge ended.  Edge by edge: the pieces of a B-spline the
    wire runs against its parameter, judged one by one, came in reversed order (a fan
    hub's blades: a 0.72 mm "gap" inside one edge)."""
    def ends(pieces):
        return piece_ends(pieces[0])[0], piece_ends(pieces[-1])[1]

    def flip(pieces):
        return [reversed_piece(p) for p in reversed(pieces)]

    edges = [pieces for pieces in edges if pieces]
    if len(edges) < 2:
        return [p for pieces in edges for p in pieces]
    out = [edges[0]]
    a0, b0 = ends(edges[0])
    a1, b1 = ends(edges[1])
    if min(np.hypot(*(a0 - a1)), np.hypot(*(a0 - b1))) < min(np.hypot(*(b0 - a1)),
                                                              np.hypot(*(b0 - b1))):
        out[0] = flip(edges[0])
    for pieces in edges[1:]:
        end = ends(out[-1])[1]
        a, b = ends(pieces)
        out.append(pieces if np.hypot(*(a - end)) <= np.hypot(*(b - end)) else flip(pieces))
    return [p for pieces in out for p in pieces]


def to_global(placement, xy):
    """FreeCAD vectors of 2D points in the source plane."""
    return [placement.multVec(FreeCAD.Vector(float(x), float(y), 0.0)) for x, y in xy]
