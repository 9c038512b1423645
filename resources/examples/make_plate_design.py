# SPDX-License-Identifier: LGPL-2.1-or-later
"""Makes resources/examples/plate_design.FCStd (run: freecadcmd make_plate_design.py).

A constrained sketch "Plate" in the XZ plane: a 100 x 50 mm plate with a 20 mm hole in
the middle (quadcnn_wb.freecad.sketches), with named constraints "Width", "Height" and
"HoleRadius" that a demo or a user can edit.  The committed .FCStd was made by this script.
"""

import os

import FreeCAD

from quadcnn_wb.freecad.sketches import plate_with_hole

V = FreeCAD.Vector
HERE = os.path.dirname(os.path.abspath(__file__)) if "__file__" in globals() else \
    os.path.join(os.getcwd(), "resources", "examples")

doc = FreeCAD.newDocument("plate_design")
plate_with_hole(doc, 100.0, 50.0, 10.0, FreeCAD.Placement(V(0, 0, 0),
                                                         FreeCAD.Rotation(V(1, 0, 0), 90)))
doc.saveAs(os.path.join(HERE, "plate_design.FCStd"))
