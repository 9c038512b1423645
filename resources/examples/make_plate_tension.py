# SPDX-License-Identifier: LGPL-2.1-or-later
"""Makes resources/examples/plate_tension.FCStd (run: freecadcmd make_plate_tension.py):
a FEM analysis (CalculiX, shell) of a plate with a hole on a QuadCNN mesh; see
quadcnn_wb/freecad/fem_example.py.  The committed .FCStd was made by this script."""

import os

import FreeCAD

from quadcnn_wb.freecad.fem_example import build

HERE = os.path.dirname(os.path.abspath(__file__)) if "__file__" in globals() else \
    os.path.join(os.getcwd(), "resources", "examples")
doc = FreeCAD.newDocument("plate_tension")
build(doc)
doc.saveAs(os.path.join(HERE, "plate_tension.FCStd"))
