"""The workbench's toolbar and menu commands (GUI only; imported by InitGui).

Each command is enabled only when its input is there: CreateMesh and ShowField need a
selected sketch or planar face (ShowField also takes a QuadCNN mesh), TrainModel a sketch
(or a mesh made from one), ExportMesh a selected QuadCNN mesh, RegenerateAll an open
document with QuadCNN meshes.
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
        FreeCADGui.ActiveDocument.setEdit(mesh.Name)  # the task panel, to tune and Apply


def _source_or_mesh_source():
    """The selected sketch/face, or the source of a selected QuadCNN mesh."""
    meshes = _selected_meshes()
    if meshes:
        from .mesh_object import source_of

        try:
            return source_of(meshes[0])
        except ValueError:
            return None
    return _selected_source()


def _selected_sketch():
    source = _source_or_mesh_source()
    if source is not None and not isinstance(source, tuple) and \
            source.TypeId.startswith("Sketcher::SketchObject"):
        return source
    return None


class ShowField:
    def GetResources(self):
        return {"Pixmap": resource_path("icons", "QuadCNN_ShowField.svg"),
                "MenuText": "Show frame field",
                "ToolTip": "Show (again: hide) the frame field of the selected shape: crosses, "
                           "singular points by valence, and the network's label-1 vectors",
                "StatusTip": "Select a sketch, a planar face or a QuadCNN mesh first"}

    def IsActive(self):
        return FreeCAD.ActiveDocument is not None and _source_or_mesh_source() is not None

    def Activated(self):
        from ..core.input.domain import DomainError
        from .field_view import toggle
        from .geometry import face_to_domain, source_shape_and_placement
        from .preferences import target_nodes

        source = _source_or_mesh_source()
        label = source[0].Label if isinstance(source, tuple) else source.Label
        try:
            face, plane, placement = source_shape_and_placement(source)
            domain = face_to_domain(face, plane, label)
            FreeCADGui.getMainWindow().statusBar().showMessage("QuadCNN: computing the field…")
            text = toggle(FreeCADGui.ActiveDocument.ActiveView, domain, placement,
                          target_nodes())
        except (DomainError, ValueError, RuntimeError) as exc:
            FreeCAD.Console.PrintError(f"{label}: {' '.join(str(exc).split())}\n")
            return
        FreeCAD.Console.PrintMessage(f"{label}: {text}\n")
        FreeCADGui.getMainWindow().statusBar().showMessage(f"QuadCNN: {text}", 8000)


class TrainModel:
    def GetResources(self):
        return {"Pixmap": resource_path("icons", "QuadCNN_TrainModel.svg"),
                "MenuText": "Train model for this design",
                "ToolTip": "Vary the selected sketch's dimensions, learn its streamlines in "
                           "the background, and use the model for its meshes",
                "StatusTip": "Select a sketch (or a QuadCNN mesh made from one) first"}

    def IsActive(self):
        return FreeCAD.ActiveDocument is not None and _selected_sketch() is not None

    def Activated(self):
        from .train_dialog import train_for

        train_for(_selected_sketch())


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
        from ..core.mesh.export import export

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


COMMANDS = {"QuadCNN_CreateMesh": CreateMesh, "QuadCNN_ShowField": ShowField,
            "QuadCNN_TrainModel": TrainModel, "QuadCNN_ExportMesh": ExportMesh,
            "QuadCNN_RegenerateAll": RegenerateAll}


def register() -> list[str]:
    for name, command in COMMANDS.items():
        FreeCADGui.addCommand(name, command())
    return list(COMMANDS)
