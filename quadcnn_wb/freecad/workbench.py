"""What the workbench sets up when FreeCAD first activates it."""

from __future__ import annotations

import FreeCAD


def initialize(workbench) -> None:
    """Register the QuadCNN_* commands and build the QuadCNN toolbar and menu."""
    import FreeCADGui

    from . import commands
    from .environment import resource_path

    names = commands.register()
    workbench.appendToolbar("QuadCNN", names)
    workbench.appendMenu("QuadCNN", names)
    FreeCADGui.addPreferencePage(resource_path("ui", "QuadCNNPreferences.ui"), "QuadCNN")
    FreeCAD.Console.PrintLog("QuadCNN workbench initialised\n")
