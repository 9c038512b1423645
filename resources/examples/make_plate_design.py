# SPDX-License-Identifier: LGPL-2.1-or-later
"""Makes resources/examples/plate_design.FCStd (run: freecadcmd make_plate_design.py).

A fully constrained sketch "Plate": a 100 x 50 mm plate with a 20 mm hole in the middle,
its width and hole diameter named constraints ("Width", "HoleDiameter") so a demo or a
user can edit them.  The committed .FCStd was made by this script.
"""

import os

import FreeCAD
import Part
import Sketcher

V = FreeCAD.Vector
HERE = os.path.dirname(os.path.abspath(__file__)) if "__file__" in globals() else \
    os.path.join(os.getcwd(), "resources", "examples")

doc = FreeCAD.newDocument("plate_design")
sk = doc.addObject("Sketcher::SketchObject", "Plate")
sk.Placement = FreeCAD.Placement(V(0, 0, 0), FreeCAD.Rotation(V(1, 0, 0), 90))  # XZ plane
pts = [V(0, 0, 0), V(100, 0, 0), V(100, 50, 0), V(0, 50, 0)]
for a, b in zip(pts, pts[1:] + pts[:1]):
    sk.addGeometry(Part.LineSegment(a, b))
for i in range(4):
    sk.addConstraint(Sketcher.Constraint("Coincident", i, 2, (i + 1) % 4, 1))
for i, kind in enumerate(("Horizontal", "Vertical", "Horizontal", "Vertical")):
    sk.addConstraint(Sketcher.Constraint(kind, i))
sk.addConstraint(Sketcher.Constraint("Coincident", 0, 1, -1, 1))
width = sk.addConstraint(Sketcher.Constraint("DistanceX", 0, 1, 0, 2, 100))
sk.renameConstraint(width, "Width")
sk.addConstraint(Sketcher.Constraint("DistanceY", 1, 1, 1, 2, 50))
sk.addGeometry(Part.Circle(V(50, 25, 0), V(0, 0, 1), 10))
hole = sk.addConstraint(Sketcher.Constraint("Diameter", 4, 20))
sk.renameConstraint(hole, "HoleDiameter")
sk.addConstraint(Sketcher.Constraint("DistanceX", -1, 1, 4, 3, 50))
sk.addConstraint(Sketcher.Constraint("DistanceY", -1, 1, 4, 3, 25))
doc.recompute()
doc.saveAs(os.path.join(HERE, "plate_design.FCStd"))
