# SPDX-License-Identifier: LGPL-2.1-or-later
"""Makes the tests/corpus/sketch_*.brep faces (run: freecadcmd tests/corpus/make_sketch_parts.py).

Parts built the way a FreeCAD user builds them, so that the corpus also holds faces as
FreeCAD itself hands them to the workbench: constrained Sketcher profiles padded with
PartDesign, 3D fillets and chamfers on the pad's vertical edges, Sketcher fillets (tangent
arcs the solver places), an involute gear from PartDesign's gear feature, and a Part
workbench boolean (fuse with Refine, then cut).  Each part's top planar face (normal +z,
highest) is written with ``face.exportBrep``, as extract_face.py does for public parts.

    sketch_bracket         L bracket, three holes, PartDesign fillets (convex R6, concave R10)
    sketch_slot_plate      plate with an obround slot (tangent arcs) and a 6-hole bolt circle
    sketch_keyhole_plate   plate with chamfered corners, a keyhole and two holes
    sketch_gasket          gasket frame with six bolt bosses (Part fuse + cut, refined)
    sketch_lever           lever: two bosses joined by a tangent line and a tangent concave arc
    sketch_tslot_profile   20 x 20 T-slot extrusion profile, Sketcher-filleted corners
    sketch_gear            18-tooth involute spur gear, module 2.5, bore with a keyway
"""

import math
import os
import sys

import FreeCAD
import Part
import Sketcher

V = FreeCAD.Vector
Z = V(0, 0, 1)
HERE = os.path.dirname(os.path.abspath(__file__)) if "__file__" in globals() else \
    os.path.join(os.getcwd(), "tests", "corpus")


# --- helpers: what a user does with the mouse, in script form ------------------------------

def new_body(doc, name):
    body = doc.addObject("PartDesign::Body", name)
    return body


def xy_sketch(body, name):
    sketch = body.newObject("Sketcher::SketchObject", name)
    plane = [f for f in body.Origin.OriginFeatures if f.Role == "XY_Plane"][0]
    sketch.Support = (plane, [""])
    sketch.MapMode = "FlatFace"
    return sketch


def add_polygon(sketch, points):
    """A closed polyline with coincident corners and horizontal/vertical constraints."""
    first = sketch.GeometryCount
    n = len(points)
    for k in range(n):
        p, q = points[k], points[(k + 1) % n]
        sketch.addGeometry(Part.LineSegment(V(p[0], p[1], 0), V(q[0], q[1], 0)), False)
    for k in range(n):
        sketch.addConstraint(Sketcher.Constraint("Coincident", first + k, 2,
                                                 first + (k + 1) % n, 1))
    for k in range(n):
        p, q = points[k], points[(k + 1) % n]
        if abs(p[1] - q[1]) < 1e-12:
            sketch.addConstraint(Sketcher.Constraint("Horizontal", first + k))
        elif abs(p[0] - q[0]) < 1e-12:
            sketch.addConstraint(Sketcher.Constraint("Vertical", first + k))
    return list(range(first, first + n))


def add_circle(sketch, center, radius):
    g = sketch.addGeometry(Part.Circle(V(center[0], center[1], 0), Z, radius), False)
    sketch.addConstraint(Sketcher.Constraint("Radius", g, radius))
    return g


def add_arc(sketch, center, radius, a0, a1):
    """Arc from angle a0 counter-clockwise to a1 (radians)."""
    circle = Part.Circle(V(center[0], center[1], 0), Z, radius)
    return sketch.addGeometry(Part.ArcOfCircle(circle, a0, a1), False)


def add_line(sketch, p, q):
    return sketch.addGeometry(Part.LineSegment(V(p[0], p[1], 0), V(q[0], q[1], 0)), False)


def joined(sketch, g1, end1, g2, end2, tangent=False):
    kind = "Tangent" if tangent else "Coincident"
    sketch.addConstraint(Sketcher.Constraint(kind, g1, end1, g2, end2))


def fillet_corner(sketch, line1, line2, corner, radius):
    """The Sketcher fillet tool on the corner where line1 ends and line2 starts."""
    def near(g):
        seg = sketch.Geometry[g]
        p, q = seg.StartPoint, seg.EndPoint
        if (q - corner).Length < (p - corner).Length:
            p, q = q, p
        return p + (q - p) * 0.1
    sketch.fillet(line1, line2, near(line1), near(line2), radius)


def vertical_edges_at(shape, points, tol=1e-6):
    """Names of the vertical edges through the given (x, y) points."""
    names = []
    for k, edge in enumerate(shape.Edges, start=1):
        if not isinstance(edge.Curve, Part.Line):
            continue
        a, b = edge.Vertexes[0].Point, edge.Vertexes[-1].Point
        if abs(a.x - b.x) > tol or abs(a.y - b.y) > tol:
            continue
        if any(abs(a.x - x) < tol and abs(a.y - y) < tol for x, y in points):
            names.append(f"Edge{k}")
    return names


def top_face(shape):
    """The planar face facing +z that lies highest (the largest one on a tie)."""
    candidates = []
    for face in shape.Faces:
        if not isinstance(face.Surface, Part.Plane):
            continue
        normal = face.normalAt(*face.ParameterRange[0:3:2])
        if normal.z < 1 - 1e-9:
            continue
        candidates.append((round(face.CenterOfMass.z, 9), face.Area, face))
    return max(candidates, key=lambda t: t[:2])[2]


def check_solved(sketch):
    status = sketch.solve()
    if status != 0:
        print(f"warning: sketch {sketch.Name} does not solve (status {status})")


# --- the parts -----------------------------------------------------------------------------

def bracket(doc):
    body = new_body(doc, "Bracket")
    sk = xy_sketch(body, "BracketSketch")
    outline = [(0, 0), (100, 0), (100, 25), (25, 25), (25, 80), (0, 80)]
    add_polygon(sk, outline)
    for c in ((12.5, 12.5), (85, 12.5), (12.5, 65)):
        add_circle(sk, c, 4.0)
    check_solved(sk)
    pad = body.newObject("PartDesign::Pad", "BracketPad")
    pad.Profile = sk
    pad.Length = 6
    doc.recompute()
    convex = body.newObject("PartDesign::Fillet", "OuterFillet")
    convex.Base = (pad, vertical_edges_at(pad.Shape, [(0, 0), (100, 0), (100, 25),
                                                      (25, 80), (0, 80)]))
    convex.Radius = 6
    doc.recompute()
    concave = body.newObject("PartDesign::Fillet", "InnerFillet")
    concave.Base = (convex, vertical_edges_at(convex.Shape, [(25, 25)]))
    concave.Radius = 10
    doc.recompute()
    return body.Shape


def slot_plate(doc):
    body = new_body(doc, "SlotPlate")
    sk = xy_sketch(body, "SlotPlateSketch")
    add_polygon(sk, [(0, 0), (120, 0), (120, 80), (0, 80)])
    # obround slot: two half circles joined by tangent lines
    r, y, x0, x1 = 5.0, 40.0, 20.0, 40.0
    right = add_arc(sk, (x1, y), r, -math.pi / 2, math.pi / 2)
    top = add_line(sk, (x1, y + r), (x0, y + r))
    left = add_arc(sk, (x0, y), r, math.pi / 2, 3 * math.pi / 2)
    bottom = add_line(sk, (x0, y - r), (x1, y - r))
    joined(sk, right, 2, top, 1, tangent=True)
    joined(sk, top, 2, left, 1, tangent=True)
    joined(sk, left, 2, bottom, 1, tangent=True)
    joined(sk, bottom, 2, right, 1, tangent=True)
    sk.addConstraint(Sketcher.Constraint("Equal", right, left))
    # bolt circle: bore and six holes on a 25 mm radius
    add_circle(sk, (80, 40), 12.0)
    for k in range(6):
        a = math.radians(30 + 60 * k)
        add_circle(sk, (80 + 25 * math.cos(a), 40 + 25 * math.sin(a)), 3.5)
    check_solved(sk)
    pad = body.newObject("PartDesign::Pad", "SlotPlatePad")
    pad.Profile = sk
    pad.Length = 8
    doc.recompute()
    return body.Shape


def keyhole_plate(doc):
    body = new_body(doc, "KeyholePlate")
    sk = xy_sketch(body, "KeyholeSketch")
    add_polygon(sk, [(0, 0), (100, 0), (100, 60), (0, 60)])
    cx, cy, big, small, neck = 50.0, 38.0, 6.0, 3.0, 14.0
    half = small
    a = math.asin(half / big)  # where the neck meets the big circle, from straight down
    head = add_arc(sk, (cx, cy), big, -math.pi / 2 + a, 3 * math.pi / 2 - a)
    y_meet = cy - big * math.cos(a)
    left = add_line(sk, (cx - half, y_meet), (cx - half, cy - neck))
    foot = add_arc(sk, (cx, cy - neck), small, math.pi, 2 * math.pi)
    right = add_line(sk, (cx + half, cy - neck), (cx + half, y_meet))
    joined(sk, head, 2, left, 1)
    joined(sk, left, 2, foot, 1, tangent=True)
    joined(sk, foot, 2, right, 1, tangent=True)
    joined(sk, right, 2, head, 1)
    sk.addConstraint(Sketcher.Constraint("Vertical", left))
    sk.addConstraint(Sketcher.Constraint("Vertical", right))
    add_circle(sk, (15, 15), 4.0)
    add_circle(sk, (85, 15), 4.0)
    check_solved(sk)
    pad = body.newObject("PartDesign::Pad", "KeyholePad")
    pad.Profile = sk
    pad.Length = 5
    doc.recompute()
    chamfer = body.newObject("PartDesign::Chamfer", "CornerChamfer")
    chamfer.Base = (pad, vertical_edges_at(pad.Shape, [(0, 0), (100, 0), (100, 60), (0, 60)]))
    chamfer.Size = 8
    doc.recompute()
    return body.Shape


def gasket(doc):
    """Part workbench: box minus box, fused with boss cylinders (Refine), bolt holes cut."""
    outer = doc.addObject("Part::Box", "GasketOuter")
    outer.Length, outer.Width, outer.Height = 120, 80, 3
    inner = doc.addObject("Part::Box", "GasketWindow")
    inner.Length, inner.Width, inner.Height = 90, 50, 3
    inner.Placement.Base = V(15, 15, 0)
    frame = doc.addObject("Part::Cut", "GasketFrame")
    frame.Base, frame.Tool = outer, inner
    centers = [(0, 0), (60, 0), (120, 0), (120, 80), (60, 80), (0, 80)]
    bosses, holes = [], []
    for k, (x, y) in enumerate(centers):
        boss = doc.addObject("Part::Cylinder", f"Boss{k}")
        boss.Radius, boss.Height = 9, 3
        boss.Placement.Base = V(x, y, 0)
        bosses.append(boss)
        hole = doc.addObject("Part::Cylinder", f"BoltHole{k}")
        hole.Radius, hole.Height = 3.5, 3
        hole.Placement.Base = V(x, y, 0)
        holes.append(hole)
    fused = doc.addObject("Part::MultiFuse", "GasketWithBosses")
    fused.Shapes = [frame] + bosses
    fused.Refine = True
    drills = doc.addObject("Part::MultiFuse", "BoltHoles")
    drills.Shapes = holes
    cut = doc.addObject("Part::Cut", "Gasket")
    cut.Base, cut.Tool = fused, drills
    cut.Refine = True
    doc.recompute()
    return cut.Shape


def lever(doc):
    """Two bosses (R20 and R10, 80 apart) joined by a tangent line on top and a concave
    R50 arc below, tangent to both: the tangent points are the solver's to keep."""
    body = new_body(doc, "Lever")
    sk = xy_sketch(body, "LeverSketch")
    r1, r2, d, r3 = 20.0, 10.0, 80.0, 50.0
    nx = (r1 - r2) / d  # upper common tangent: unit normal n with n . (c2 - c1) = r1 - r2
    ny = math.sqrt(1 - nx * nx)
    top_angle = math.atan2(ny, nx)
    x3 = ((r1 + r3) ** 2 - (r2 + r3) ** 2 + d * d) / (2 * d)  # the concave arc's center
    y3 = -math.sqrt((r1 + r3) ** 2 - x3 * x3)
    a1 = math.atan2(y3, x3)  # from boss 1 towards the arc's center
    a2 = math.atan2(y3, x3 - d)
    big = add_arc(sk, (0, 0), r1, top_angle, a1 + 2 * math.pi)
    small = add_arc(sk, (d, 0), r2, a2, top_angle + 2 * math.pi)
    b1 = math.atan2(-y3, -x3)  # from the arc's center towards boss 1
    b2 = math.atan2(-y3, d - x3)
    concave = add_arc(sk, (x3, y3), r3, b2, b1)
    top = add_line(sk, (d + r2 * nx, r2 * ny), (r1 * nx, r1 * ny))
    joined(sk, top, 2, big, 1, tangent=True)
    joined(sk, big, 2, concave, 2, tangent=True)
    joined(sk, concave, 1, small, 1, tangent=True)
    joined(sk, small, 2, top, 1, tangent=True)
    add_circle(sk, (0, 0), 10.0)
    add_circle(sk, (d, 0), 5.0)
    check_solved(sk)
    pad = body.newObject("PartDesign::Pad", "LeverPad")
    pad.Profile = sk
    pad.Length = 10
    doc.recompute()
    return body.Shape


def tslot_profile(doc):
    """A 20 x 20 T-slot extrusion profile; the pad's end face is the profile."""
    body = new_body(doc, "TSlot")
    sk = xy_sketch(body, "TSlotSketch")
    side = [(3.1, 10), (3.1, 8.2), (5.5, 8.2), (5.5, 6.5), (3.0, 4.0),
            (-3.0, 4.0), (-5.5, 6.5), (-5.5, 8.2), (-3.1, 8.2), (-3.1, 10)]
    points = []
    for quarter in range(4):  # top, left, bottom, right; counter-clockwise
        c, s = [(1, 0), (0, 1), (-1, 0), (0, -1)][quarter]
        points.append((10 * c - 10 * s, 10 * s + 10 * c))  # the corner before this side
        points.extend((x * c - y * s, x * s + y * c) for x, y in side)
    points = [(round(x, 12) + 0.0, round(y, 12) + 0.0) for x, y in points]
    lines = add_polygon(sk, points)
    n = len(lines)
    for corner in range(4):
        k = corner * (len(side) + 1)  # point k is an outer corner: line k-1 ends there
        fillet_corner(sk, lines[(k - 1) % n], lines[k], V(*points[k], 0), 1.5)
    add_circle(sk, (0, 0), 2.1)
    check_solved(sk)
    pad = body.newObject("PartDesign::Pad", "TSlotPad")
    pad.Profile = sk
    pad.Length = 30
    doc.recompute()
    return body.Shape


def gear(doc):
    import InvoluteGearFeature  # PartDesign's gear (Part Design > Involute gear...)

    body = new_body(doc, "Gear")
    profile = body.newObject("Part::Part2DObjectPython", "InvoluteGear")
    InvoluteGearFeature._InvoluteGear(profile)
    profile.NumberOfTeeth = 18
    profile.Modules = "2.5 mm"
    doc.recompute()
    pad = body.newObject("PartDesign::Pad", "GearPad")
    pad.Profile = profile
    pad.Length = 10
    doc.recompute()
    sk = xy_sketch(body, "BoreSketch")
    r, w, depth = 8.0, 5.0, 10.3
    a = math.asin(w / 2 / r)
    y0 = r * math.cos(a)
    arc = add_arc(sk, (0, 0), r, math.pi / 2 + a, 5 * math.pi / 2 - a)
    right = add_line(sk, (w / 2, y0), (w / 2, depth))
    top = add_line(sk, (w / 2, depth), (-w / 2, depth))
    left = add_line(sk, (-w / 2, depth), (-w / 2, y0))
    joined(sk, arc, 2, right, 1)
    joined(sk, right, 2, top, 1)
    joined(sk, top, 2, left, 1)
    joined(sk, left, 2, arc, 1)
    check_solved(sk)
    pocket = body.newObject("PartDesign::Pocket", "Bore")
    pocket.Profile = sk
    pocket.Type = "ThroughAll"
    pocket.Midplane = True
    doc.recompute()
    return body.Shape


PARTS = {
    "bracket": bracket,
    "slot_plate": slot_plate,
    "keyhole_plate": keyhole_plate,
    "gasket": gasket,
    "lever": lever,
    "tslot_profile": tslot_profile,
    "gear": gear,
}


def main():
    for name, build in PARTS.items():
        doc = FreeCAD.newDocument(name)
        shape = build(doc)
        broken = [o.Name for o in doc.Objects if "Invalid" in o.State or "Error" in o.State]
        if broken or shape.isNull() or not shape.isValid():
            print(f"error: {name}: the model does not rebuild ({', '.join(broken)})")
            raise SystemExit(1)
        if not shape.isValid():
            raise SystemExit(f"{name}: the solid is not valid")
        face = top_face(shape)
        out = os.path.join(HERE, f"sketch_{name}.brep")
        face.exportBrep(out)
        kinds = {}
        for edge in face.Edges:
            kind = type(edge.Curve).__name__
            kinds[kind] = kinds.get(kind, 0) + 1
        print(f"{out}: area {face.Area:.3f}, {len(face.Wires)} wires, {len(face.Edges)} edges "
              f"{kinds}, {os.path.getsize(out)} bytes")
        FreeCAD.closeDocument(doc.Name)
    sys.stdout.flush()


main()
