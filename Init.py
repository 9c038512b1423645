# SPDX-License-Identifier: LGPL-2.1-or-later
"""QuadCNN App-side start-up: make dependencies importable and register the tests.

FreeCAD exec()s this file at start-up; the work lives in quadcnn_wb.
"""

import FreeCAD

from quadcnn_wb.freecad import environment

environment.add_project_packages()

FreeCAD.__unit_test__ += ["TestQuadCNN"]
