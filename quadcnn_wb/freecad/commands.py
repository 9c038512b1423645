"""The workbench's toolbar and menu commands (GUI only; imported by InitGui).

Each command is enabled only when its input is there: CreateMesh needs a selected sketch
or planar face, ExportMesh a selected QuadCNN mesh, RegenerateAll an open document with
QuadCNN meshes.
"""

from __future__ import annotations

import FreeCAD
import FreeCADGui

from .environment import resource_path


def _selected_source():
    """(sketch) or (object, 'FaceN') from the selection, or None."""
    for sel in FreeCADGui.Selection.getSelectionEx():
        obj = sel.Object
        faces = [n for n in sel.SubElementNames if n.startswith("Face")]
        if faces:
            return (obj, faces[0])
        if obj.TypeId.startswith("Sketcher::SketchObject"):
            return obj
        if hasattr(obj, "Shape") and len(getattr(obj.Shape, "Faces", [])) == 1 \
                and not _is_quad_mesh(obj):
            return obj
    return None


def _is_quad_mesh(obj) -> bool:
    from .mesh_object import QuadMeshProxy

    return isinstance(getattr(obj, "Proxy", None), QuadMeshProxy)


def _selected_meshes():
    return [o for o in FreeCADGui.Selection.getSelection() if _is_quad_mesh(o)]


class CreateMesh:
    def GetResources(self):
        return {"Pixmap": resource_path("icons", "QuadCNN_CreateMesh.svg"),
                "MenuText": "Create quad mesh",
                "ToolTip": "Block-structured quad mesh of the selected sketch or planar face; "
                           "it regenerates when the sketch changes",
                "StatusTip": "Select a closed sketch or a planar face first"}

    def IsActive(self):
        return FreeCAD.ActiveDocument is not None and _selected_source() is not None

    def Activated(self):
        from .mesh_object import make_quad_mesh

        doc = FreeCAD.ActiveDocument
        source = _selected_source()
        doc.openTransaction("Create QuadCNN mesh")
        mesh = make_quad_mesh(doc, source)
        doc.commitTransaction()
        doc.recompute()
        if not mesh.isValid():
            FreeCAD.Console.PrintError(f"{mesh.Label}: {mesh.Status}\n")
        FreeCADGui.Selection.clearSelection()
        FreeCADGui.Selection.addSelection(mesh)


class ExportMesh:
    def GetResources(self):
        return {"Pixmap": resource_path("icons", "QuadCNN_ExportMesh.svg"),
                "MenuText": "Export quad mesh",
                "ToolTip": "Write the selected QuadCNN mesh as .inp, .msh, .vtk or .unv",
                "StatusTip": "Select a QuadCNN mesh first"}

    def IsActive(self):
        return len(_selected_meshes()) == 1

    def Activated(self):
        from PySide import QtGui

        mesh = _selected_meshes()[0]
        path, _ = QtGui.QFileDialog.getSaveFileName(
            FreeCADGui.getMainWindow(), "Export quad mesh", f"{mesh.Label}.inp",
            "CalculiX/Abaqus (*.inp);;gmsh (*.msh);;VTK (*.vtk);;UNV (*.unv)")
        if path:
            export_mesh(mesh, path)


def export_mesh(mesh, path: str) -> None:
    """Our writers (with block and boundary sets) when the last result is in memory."""
    result = getattr(mesh.Proxy, "last_result", None)
    if result is not None and not path.lower().endswith(".unv"):
        from ..core.export import export

        export(result, path)
    else:
        mesh.FemMesh.write(path)
    FreeCAD.Console.PrintMessage(f"{mesh.Label}: written to {path}\n")


class RegenerateAll:
    def GetResources(self):
        return {"Pixmap": resource_path("icons", "QuadCNN_RegenerateAll.svg"),
                "MenuText": "Regenerate all quad meshes",
                "ToolTip": "Recompute every QuadCNN mesh of the active document",
                "StatusTip": "Regenerates every QuadCNN mesh of the active document"}

    def IsActive(self):
        from .batch import quad_mesh_objects

        doc = FreeCAD.ActiveDocument
        return doc is not None and bool(quad_mesh_objects(doc))

    def Activated(self):
        from .batch import regenerate_document, summary

        FreeCAD.Console.PrintMessage(summary(regenerate_document(FreeCAD.ActiveDocument))
                                     + "\n")


COMMANDS = {"QuadCNN_CreateMesh": CreateMesh, "QuadCNN_ExportMesh": ExportMesh,
            "QuadCNN_RegenerateAll": RegenerateAll}


def register() -> list[str]:
    for name, command in COMMANDS.items():
        FreeCADGui.addCommand(name, command())
    return list(COMMANDS)
