"""Parametric sketches the examples and tests are built from."""

from __future__ import annotations

import FreeCAD
import Part
import Sketcher

V = FreeCAD.Vector


def plate_with_hole(doc, width: float, height: float, radius: float, placement=None,
                    name: str = "Plate"):
    """A constrained rectangle with a centred hole; named constraints "Width", "Height",
    "HoleRadius".  Returns (sketch, width constraint index, radius constraint index)."""
    sk = doc.addObject("Sketcher::SketchObject", name)
    if placement is not None:
        sk.Placement = placement
    pts = [V(0, 0, 0), V(width, 0, 0), V(width, height, 0), V(0, height, 0)]
    for a, b in zip(pts, pts[1:] + pts[:1]):
        sk.addGeometry(Part.LineSegment(a, b))
    for i in range(4):
        sk.addConstraint(Sketcher.Constraint("Coincident", i, 2, (i + 1) % 4, 1))
    for i, kind in enumerate(("Horizontal", "Vertical", "Horizontal", "Vertical")):
        sk.addConstraint(Sketcher.Constraint(kind, i))
    sk.addConstraint(Sketcher.Constraint("Coincident", 0, 1, -1, 1))
    width_c = sk.addConstraint(Sketcher.Constraint("DistanceX", 0, 1, 0, 2, width))
    sk.renameConstraint(width_c, "Width")
    height_c = sk.addConstraint(Sketcher.Constraint("DistanceY", 1, 1, 1, 2, height))
    sk.renameConstraint(height_c, "Height")
    sk.addGeometry(Part.Circle(V(width / 2, height / 2, 0), V(0, 0, 1), radius))
    radius_c = sk.addConstraint(Sketcher.Constraint("Radius", 4, radius))
    sk.renameConstraint(radius_c, "HoleRadius")
    doc.recompute()
    return sk, width_c, radius_c
