"""The mesh object's task panel (opens on create and on double-click; GUI only).

Edits go to the object's properties; Apply regenerates without closing and shows the
result in the status line, OK applies and closes, Cancel closes and undoes the edits of
this session.  Regeneration shows FreeCAD's busy progress indicator (the mesh object's
execute starts one), and on a 2048-node background takes well under a second.
"""

from __future__ import annotations

import json
from pathlib import Path

import FreeCAD
import FreeCADGui

from .environment import resource_path

METHODS = ("auto", "cnn", "numerical")
FOUND = "found by topology (user, then shipped)"
EMBEDDED = "embedded in this object"


def status_text(obj) -> str:
    """One line a user can read at a glance: blocks, quads, quality, method, time."""
    if not obj.Status:
        return "not meshed yet"
    if obj.Status.startswith("error"):
        return obj.Status
    try:
        total = json.loads(obj.Timings or "{}").get("total", 0.0)
    except json.JSONDecodeError:
        total = 0.0
    fallbacks = len(obj.Fallbacks)
    source = f" ({obj.ModelEntry})" if obj.MethodUsed == "cnn" and obj.ModelEntry else ""
    text = (f"{obj.Blocks} blocks, {obj.Quads} quads, min scaled Jacobian "
            f"{obj.MinScaledJacobian:.3f}, method {obj.MethodUsed}{source}, "
            f"{fallbacks} fallback{'s' if fallbacks != 1 else ''}, {total:.2f} s")
    return text if obj.Status == "ok" else f"{text}; {obj.Status}"


class QuadMeshTaskPanel:
    def __init__(self, obj):
        self.obj = obj
        self.form = FreeCADGui.PySideUic.loadUi(resource_path("ui", "QuadMeshTask.ui"))
        self.form.setWindowTitle(f"QuadCNN mesh: {obj.Label}")
        self.form.method.addItems(list(METHODS))
        self.form.loadModel.clicked.connect(self.load_model)
        self.refresh_models()
        self.show_properties()
        obj.Document.openTransaction(f"Edit {obj.Label}")

    # -- between the form and the object --------------------------------------------------
    def refresh_models(self):
        from ..infer.models import available_models

        box = self.form.model
        box.clear()
        box.addItem(FOUND, "")
        if self.obj.Model:
            box.addItem(EMBEDDED, "embedded")
        for entry in available_models():
            box.addItem(f"{entry.family} ({entry.origin}: {entry.path.name})", str(entry.path))
        box.setCurrentIndex(1 if self.obj.Model else 0)

    def show_properties(self):
        obj, form = self.obj, self.form
        form.method.setCurrentIndex(METHODS.index(obj.Method))
        form.elementSize.setValue(float(obj.ElementSize))
        form.targetNodes.setValue(int(obj.TargetNodes))
        form.smoothing.setChecked(bool(obj.Smoothing))
        form.status.setText(status_text(obj))

    def store_properties(self):
        obj, form = self.obj, self.form
        obj.Method = METHODS[form.method.currentIndex()]
        obj.ElementSize = form.elementSize.value()
        obj.TargetNodes = form.targetNodes.value()
        obj.Smoothing = form.smoothing.isChecked()
        choice = form.model.currentData()
        if not choice:
            obj.Model = ""  # clear the embedded copy: the registry decides
        elif choice != "embedded":
            obj.Model = choice  # embeds a copy of the chosen file

    def load_model(self):
        from PySide import QtGui

        path, _ = QtGui.QFileDialog.getOpenFileName(self.form, "Embed a QuadCNN model", "",
                                                    "ONNX model (*.onnx)")
        if path:
            self.obj.Model = path
            self.refresh_models()
            self.form.status.setText(f"embedded {Path(path).name}; Apply to regenerate")

    def regenerate(self):
        self.store_properties()
        self.obj.touch()
        self.obj.Document.recompute()
        self.form.status.setText(status_text(self.obj))

    # -- what the task dialog calls -------------------------------------------------------
    def getStandardButtons(self):
        from PySide import QtGui

        buttons = QtGui.QDialogButtonBox
        return int(buttons.Ok | buttons.Apply | buttons.Cancel)

    def clicked(self, button):
        from PySide import QtGui

        if button == QtGui.QDialogButtonBox.Apply:
            self.regenerate()

    def accept(self):
        self.regenerate()
        self.obj.Document.commitTransaction()
        FreeCADGui.ActiveDocument.resetEdit()
        return True

    def reject(self):
        self.obj.Document.abortTransaction()
        self.obj.Document.recompute()
        FreeCADGui.ActiveDocument.resetEdit()
        return True


CURRENT = []  # the open panel (scripts and the GUI test reach it here)


def open_panel(obj) -> QuadMeshTaskPanel:
    panel = QuadMeshTaskPanel(obj)
    CURRENT[:] = [panel]
    FreeCADGui.Control.closeDialog()
    FreeCADGui.Control.showDialog(panel)
    FreeCAD.Console.PrintLog(f"{obj.Label}: task panel open\n")
    return panel
