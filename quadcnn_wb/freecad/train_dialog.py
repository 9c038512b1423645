"""Train a model for the selected design (GUI only): a dialog for the ranges of the
sketch's dimensions, the variants made in FreeCAD (with a progress bar), then data and
training in a separate process (learn.design_train) whose progress lines drive a progress
dialog with Cancel; the GUI never waits on it.  The finished model is saved to the user
model folder and embedded in the design's QuadCNN mesh objects.
"""

from __future__ import annotations

import json
import shutil
import tempfile
from pathlib import Path

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

from .design_variants import dimensions, make_variants
from .environment import REPO_ROOT, venv_site_packages

VENV_PYTHON = REPO_ROOT / ".venv" / "bin" / "python"
INSTALL_HINT = ("Training needs PyTorch in QuadCNN's environment:\n"
                f"  {VENV_PYTHON} -m pip install -e '{REPO_ROOT}[train]'")


def torch_installed() -> bool:
    return (venv_site_packages() / "torch").is_dir()


class RangesDialog(QtGui.QDialog):
    """One ±% per driving dimension (default 20 %), the number of variants and samples."""

    def __init__(self, sketch, parent=None):
        super().__init__(parent)
        self.setWindowTitle(f"Train a model for {sketch.Label}")
        layout = QtGui.QFormLayout(self)
        self.spreads = {}
        for d in dimensions(sketch):
            box = QtGui.QDoubleSpinBox()
            box.setRange(0.0, 90.0)
            box.setSuffix(" %")
            box.setValue(20.0)
            unit = "°" if d.kind == "Angle" else " mm"
            value = d.value * 57.29577951308232 if d.kind == "Angle" else d.value
            layout.addRow(f"{d.name} ({value:g}{unit}) ±", box)
            self.spreads[d.index] = box
        self.variants = QtGui.QSpinBox()
        self.variants.setRange(2, 5000)
        self.variants.setValue(100)
        layout.addRow("Design variants", self.variants)
        self.samples = QtGui.QSpinBox()
        self.samples.setRange(10, 20000)
        self.samples.setValue(400)
        layout.addRow("Training samples (augmented)", self.samples)
        self.epochs = QtGui.QSpinBox()
        self.epochs.setRange(1, 500)
        self.epochs.setValue(8)
        layout.addRow("Epochs", self.epochs)
        buttons = QtGui.QDialogButtonBox(QtGui.QDialogButtonBox.Ok |
                                         QtGui.QDialogButtonBox.Cancel)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout.addRow(buttons)

    def spread(self) -> dict:
        return {i: box.value() / 100.0 for i, box in self.spreads.items() if box.value() > 0}


class TrainingRun(QtCore.QObject):
    """The training process and its progress dialog; lives until the process ends."""

    RUNNING = []  # keeps runs alive while their process works

    def __init__(self, sketch, variants_path: Path, model_path: Path, samples, epochs):
        super().__init__()
        self.sketch_name, self.doc_name = sketch.Name, sketch.Document.Name
        self.label = sketch.Label
        self.model_path = model_path
        self.workdir = variants_path.parent
        self.dialog = QtGui.QProgressDialog(f"Training a model for {self.label}…", "Cancel",
                                            0, 1000, FreeCADGui.getMainWindow())
        self.dialog.setWindowTitle("QuadCNN training")
        self.dialog.setMinimumDuration(0)
        self.dialog.canceled.connect(self.cancel)
        self.process = QtCore.QProcess(self)
        self.process.setWorkingDirectory(str(REPO_ROOT))
        self.process.readyReadStandardOutput.connect(self.read_progress)
        self.process.finished.connect(self.finished)
        self.error = ""
        self.cancelled = False
        self.process.start(str(VENV_PYTHON), ["-m", "quadcnn_wb.learn.design_train",
                                              str(variants_path), "-o", str(model_path),
                                              "--samples", str(samples), "--epochs",
                                              str(epochs)])
        TrainingRun.RUNNING.append(self)

    def read_progress(self):
        while self.process.canReadLine():
            line = bytes(self.process.readLine()).decode(errors="replace").strip()
            if line.startswith("progress "):
                _, fraction, text = (line.split(" ", 2) + [""])[:3]
                self.dialog.setValue(int(1000 * float(fraction)))
                self.dialog.setLabelText(f"Training a model for {self.label}: {text}")

    def cancel(self):
        self.cancelled = True
        self.process.kill()

    def finished(self, code, status=None):
        self.dialog.reset()
        stderr = bytes(self.process.readAllStandardError()).decode(errors="replace")
        try:
            if self.cancelled:
                FreeCAD.Console.PrintWarning(f"QuadCNN: training for {self.label} cancelled\n")
            elif code != 0 or not self.model_path.is_file():
                lines = [s for s in stderr.splitlines() if s.startswith("error:")]
                message = lines[-1] if lines else (stderr.strip().splitlines() or ["failed"])[-1]
                self.error = message
                FreeCAD.Console.PrintError(f"QuadCNN: training failed: {message}\n")
                box = QtGui.QMessageBox(QtGui.QMessageBox.Warning, "QuadCNN training",
                                        message, parent=FreeCADGui.getMainWindow())
                box.setModal(False)  # tell, but never hold the GUI
                box.show()
                self.message_box = box
            else:
                self.install()
        finally:
            shutil.rmtree(self.workdir, ignore_errors=True)
            TrainingRun.RUNNING.remove(self)

    def install(self):
        """Save the model to the user folder and embed it in the design's meshes."""
        from ..infer.user_folder import user_model_folder

        folder = user_model_folder()
        folder.mkdir(parents=True, exist_ok=True)
        target = folder / f"design_{self.label}.onnx"
        shutil.copyfile(self.model_path, target)
        shutil.copyfile(self.model_path.with_suffix(".json"), target.with_suffix(".json"))
        meta = json.loads(target.with_suffix(".json").read_text())
        doc = FreeCAD.getDocument(self.doc_name)
        sketch = doc.getObject(self.sketch_name) if doc else None
        embedded = 0
        if sketch is not None:
            from .batch import quad_mesh_objects

            for mesh in quad_mesh_objects(doc):
                if mesh.Source and mesh.Source[0] == sketch:
                    mesh.Model = str(target)
                    embedded += 1
        iou = meta.get("metrics_test_split", {}).get("iou", 0.0)
        FreeCAD.Console.PrintMessage(f"QuadCNN: model for {self.label} saved to {target} "
                                     f"(test IoU {iou:.3f}); embedded in {embedded} mesh "
                                     f"object(s)\n")


def train_for(sketch):
    """The whole TrainModel command, from the ranges dialog to the background process."""
    main = FreeCADGui.getMainWindow()
    if not torch_installed():
        QtGui.QMessageBox.information(main, "QuadCNN training", INSTALL_HINT)
        return None
    dialog = RangesDialog(sketch, main)
    if dialog.exec_() != QtGui.QDialog.Accepted:
        return None
    count = dialog.variants.value()
    progress = QtGui.QProgressDialog("Making design variants…", "", 0, count, main)
    progress.setCancelButton(None)
    progress.setMinimumDuration(0)

    def report(done, total):
        progress.setValue(done)
        QtGui.QApplication.processEvents()

    try:
        domains, _ = make_variants(sketch, count, dialog.spread(), report=report)
    finally:
        progress.reset()
    workdir = Path(tempfile.mkdtemp(prefix="quadcnn_train_"))
    variants = workdir / "variants.json"
    variants.write_text(json.dumps({"name": sketch.Label, "domains": domains}))
    return TrainingRun(sketch, variants, workdir / "model.onnx", dialog.samples.value(),
                       dialog.epochs.value())
