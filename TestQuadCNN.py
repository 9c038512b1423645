# SPDX-License-Identifier: LGPL-2.1-or-later
"""FreeCAD-side tests, run by `freecadcmd -t TestQuadCNN` (registered in Init.py)."""

from quadcnn_wb.freecad.tests.test_app import *  # noqa: F401,F403
from quadcnn_wb.freecad.tests.test_design_variants import *  # noqa: F401,F403
from quadcnn_wb.freecad.tests.test_mesh_object import *  # noqa: F401,F403
