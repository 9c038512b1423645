# SPDX-License-Identifier: LGPL-2.1-or-later
"""QuadCNN GUI start-up: register the workbench (its commands are defined in quadcnn_wb).

FreeCAD exec()s this file with separate globals and locals, so module-level names are
not visible inside the class body or its methods: each imports what it needs itself.
"""

import FreeCADGui


class QuadCNNWorkbench(FreeCADGui.Workbench):
    from quadcnn_wb.freecad.environment import resource_path

    MenuText = "QuadCNN"
    ToolTip = "Block-structured quadrilateral meshes from sketches and planar faces"
    Icon = resource_path("icons", "QuadCNN.svg")
    del resource_path

    def Initialize(self):
        from quadcnn_wb.freecad import workbench

        workbench.initialize(self)

    def Activated(self):
        pass

    def Deactivated(self):
        pass

    def GetClassName(self):
        return "Gui::PythonWorkbench"


FreeCADGui.addWorkbench(QuadCNNWorkbench())
