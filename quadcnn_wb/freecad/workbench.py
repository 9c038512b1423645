"""What the workbench sets up when FreeCAD first activates it."""

from __future__ import annotations

import FreeCAD

COMMANDS: list[str] = []  # QuadCNN_* commands register here as they are added


def initialize(workbench) -> None:
    """Build the QuadCNN toolbar and menu from the registered commands."""
    if COMMANDS:
        workbench.appendToolbar("QuadCNN", COMMANDS)
        workbench.appendMenu("QuadCNN", COMMANDS)
    FreeCAD.Console.PrintLog("QuadCNN workbench initialised\n")
