"""Real FreeCAD: the headless test module through `freecadcmd -t`, the GUI under Xvfb."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest
from conftest import REPO

# One FreeCAD at a time: every instance writes the same user settings when it closes, so
# the suite's parallel workers (pytest-xdist) run this module's tests in one of them.
pytestmark = pytest.mark.xdist_group("freecad")

FREECAD_ENV = {**os.environ, "LANG": "C.UTF-8", "QTWEBENGINE_CHROMIUM_FLAGS": "--no-sandbox"}
# Plain freecadcmd must find our packages by itself: hide the venv from it.
for _name in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME"):
    FREECAD_ENV.pop(_name, None)


def test_freecadcmd_runs_the_registered_test_module(tmp_path):
    result = subprocess.run(["freecadcmd", "-t", "TestQuadCNN"], capture_output=True,
                            text=True, cwd=tmp_path, env=FREECAD_ENV, timeout=300)
    output = result.stdout + result.stderr
    assert result.returncode == 0, output[-3000:]
    assert "Ran " in output and "\nOK" in output, output[-3000:]
    assert "test_background_mesh_runs_in_freecad" in output


GUI_CHECK = """
import json, os, traceback
import FreeCAD, FreeCADGui
from PySide import QtGui
result = {}
try:
    result["listed"] = "QuadCNNWorkbench" in FreeCADGui.listWorkbenches()
    FreeCADGui.activateWorkbench("QuadCNNWorkbench")
    result["active"] = FreeCADGui.activeWorkbench().name()
    result["menu_text"] = FreeCADGui.activeWorkbench().MenuText
    result["commands"] = sorted(c for c in FreeCADGui.listCommands()
                                if c.startswith("QuadCNN_"))
    main = FreeCADGui.getMainWindow()
    bars = [b for b in main.findChildren(QtGui.QToolBar) if b.windowTitle() == "QuadCNN"]
    result["toolbar"] = [a.text() for a in bars[0].actions()] if bars else []
    doc = FreeCAD.openDocument(%(design)r)
    FreeCADGui.Selection.clearSelection()
    result["enabled_without_selection"] = sorted(
        c for c in result["commands"] if FreeCADGui.Command.get(c).isActive())
    FreeCADGui.Selection.addSelection(doc.getObject("Plate"))
    QtGui.QApplication.processEvents()
    result["enabled_with_sketch"] = sorted(
        c for c in result["commands"] if FreeCADGui.Command.get(c).isActive())
    if bars:
        bars[0].grab().save(os.path.join(%(shots)r, "toolbar.png"))
    FreeCADGui.runCommand("QuadCNN_CreateMesh")
    mesh = [o for o in doc.Objects if o.TypeId == "Fem::FemMeshObjectPython"][0]
    result["valid"] = mesh.isValid()
    result["quads"] = mesh.Quads
    result["mode"] = mesh.ViewObject.DisplayMode
    result["status"] = mesh.Status
    QtGui.QApplication.processEvents()
    result["colours"] = mesh.ViewObject.Proxy.block_colours
    result["singular_points"] = len(mesh.SingularPoints)
    from quadcnn_wb.freecad import task_panel
    result["panel_open"] = bool(task_panel.CURRENT) and FreeCADGui.Control.activeDialog()
    panel = task_panel.CURRENT[0]
    result["panel_status"] = panel.form.status.text()
    panel.form.targetNodes.setValue(1024)
    panel.form.method.setCurrentIndex(2)
    panel.clicked(QtGui.QDialogButtonBox.Apply)
    result["after_apply"] = [mesh.TargetNodes, mesh.Method, panel.form.status.text()]
    panel.form.resize(420, 330)
    panel.form.grab().save(os.path.join(%(shots)r, "task_panel.png"))
    panel.accept()
    result["panel_closed"] = not FreeCADGui.Control.activeDialog()
    view = FreeCADGui.ActiveDocument.ActiveView
    graph = view.getSceneGraph()
    before = graph.getNumChildren()
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(mesh)
    FreeCADGui.runCommand("QuadCNN_ShowField")
    result["field_added"] = graph.getNumChildren() - before
    mesh.ViewObject.Visibility = False
    view.viewFront()
    FreeCADGui.SendMsgToActiveView("ViewFit")
    QtGui.QApplication.processEvents()
    view.saveImage(os.path.join(%(shots)r, "field_view.png"), 800, 600, "White")
    mesh.ViewObject.Visibility = True
    FreeCADGui.runCommand("QuadCNN_ShowField")
    result["field_removed"] = graph.getNumChildren() == before
    FreeCADGui.Selection.clearSelection()
    doc.getObject(mesh.Name + "_Streamlines").ViewObject.Visibility = True
    view.viewFront()
    FreeCADGui.SendMsgToActiveView("ViewFit")
    QtGui.QApplication.processEvents()
    view.saveImage(%(image)r, 800, 600, "White")
except Exception:
    result["error"] = traceback.format_exc()
with open(%(report)r, "w") as handle:
    json.dump(result, handle)
os._exit(0)
"""

COMMANDS = ["QuadCNN_CreateMesh", "QuadCNN_ExportMesh", "QuadCNN_RegenerateAll",
            "QuadCNN_ShowField", "QuadCNN_TrainModel"]


def test_workbench_gui_creates_a_mesh_under_xvfb(tmp_path):
    import matplotlib.image

    report, image = tmp_path / "gui.json", tmp_path / "view.png"
    design = tmp_path / "design.FCStd"
    shots = os.environ.get("QUADCNN_SHOTS", str(tmp_path))
    shutil.copyfile(REPO / "resources" / "examples" / "plate_design.FCStd", design)
    script = tmp_path / "gui_check.py"
    script.write_text(GUI_CHECK % {"design": str(design), "image": str(image),
                                   "report": str(report), "shots": shots})
    result = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", "freecad",
                             str(script)], capture_output=True, text=True, cwd=tmp_path,
                            env=FREECAD_ENV, timeout=300)
    assert report.is_file(), (result.stdout + result.stderr)[-3000:]
    data = json.loads(report.read_text())
    assert "error" not in data, data.get("error")
    assert data["listed"] and data["active"] == "QuadCNNWorkbench"
    assert data["menu_text"] == "QuadCNN"
    assert data["commands"] == COMMANDS
    assert len(data["toolbar"]) == len(COMMANDS)
    # Enabled only when their input is selected.
    assert data["enabled_without_selection"] == ["QuadCNN_RegenerateAll"] or \
        data["enabled_without_selection"] == []
    assert {"QuadCNN_CreateMesh", "QuadCNN_ShowField", "QuadCNN_TrainModel"} <= \
        set(data["enabled_with_sketch"])
    assert "QuadCNN_ExportMesh" not in data["enabled_with_sketch"]
    assert data["valid"] and data["quads"] > 100
    assert data["mode"] == "Faces & Wireframe"
    assert data["colours"] >= 4  # one per block, several blocks
    assert data["singular_points"] == 4
    assert data["panel_open"] and "blocks" in data["panel_status"]
    nodes, method, status = data["after_apply"]
    assert nodes == 1024 and method == "numerical" and "method numerical" in status
    assert data["panel_closed"]
    assert data["field_added"] == 1 and data["field_removed"]
    pixels = matplotlib.image.imread(image)[..., :3]
    assert pixels.std() > 0.05, "the 3D view screenshot is blank"
    assert (pixels.max(axis=2) < 0.3).mean() > 0.01  # the quad edges (near black) are drawn
    for shot in ("toolbar.png", "task_panel.png", "field_view.png"):
        assert (Path(shots) / shot).stat().st_size > 500


def test_headless_demo_edits_regenerates_saves_and_exports(tmp_path):
    result = subprocess.run(["freecadcmd", str(REPO / "quadcnn_wb" / "freecad" / "demo.py")],
                            capture_output=True, text=True, cwd=tmp_path,
                            env={**FREECAD_ENV, "QUADCNN_OUT": str(tmp_path)}, timeout=300)
    output = result.stdout + result.stderr
    assert "after Width = 140 mm" in output, output[-3000:]
    assert "4 irregular vertices" in output
    inp = (tmp_path / "plate_design_mesh.inp").read_text()
    assert "*ELEMENT, TYPE=CPS4" in inp and "NSET=LOOP1" in inp
    assert (tmp_path / "plate_design_mesh.png").read_bytes()[:4] == b"\x89PNG"
    assert (tmp_path / "plate_design.FCStd").stat().st_size > 10_000  # now holds the mesh


def test_batch_macro_regenerates_a_folder(tmp_path):
    demo = subprocess.run(["freecadcmd", str(REPO / "quadcnn_wb" / "freecad" / "demo.py")],
                          capture_output=True, text=True, cwd=tmp_path,
                          env={**FREECAD_ENV, "QUADCNN_OUT": str(tmp_path / "made")},
                          timeout=300)
    assert demo.returncode == 0, demo.stderr[-2000:]
    folder = tmp_path / "designs"
    folder.mkdir()
    for name in ("first", "second"):
        shutil.copyfile(tmp_path / "made" / "plate_design.FCStd", folder / f"{name}.FCStd")
    macro = REPO / "resources" / "macros" / "QuadCNN_Regenerate.FCMacro"
    result = subprocess.run(["freecadcmd", str(macro)], capture_output=True, text=True,
                            cwd=tmp_path, env={**FREECAD_ENV, "QUADCNN_FOLDER": str(folder)},
                            timeout=300)
    output = result.stdout + result.stderr
    rows = [line for line in output.splitlines() if ".FCStd" in line and "QuadMesh" in line]
    assert len(rows) == 2, output[-3000:]
    assert all("numerical" in row for row in rows)
    for name in ("first", "second"):
        assert (folder / f"{name}_QuadMesh.inp").stat().st_size > 1000
        assert (folder / f"{name}_QuadMesh.vtk").stat().st_size > 1000


TRAIN_CHECK = """
import json, os, time, traceback
import FreeCAD, FreeCADGui
from PySide import QtGui
result = {}
try:
    FreeCADGui.activateWorkbench("QuadCNNWorkbench")
    doc = FreeCAD.openDocument(%(design)r)
    sketch = doc.getObject("Plate")
    from quadcnn_wb.freecad.mesh_object import make_quad_mesh
    mesh = make_quad_mesh(doc, sketch, Method="numerical")
    doc.recompute()
    from quadcnn_wb.freecad import train_dialog
    from quadcnn_wb.freecad.design_variants import dimensions, make_variants
    spread = {d.index: 0.2 for d in dimensions(sketch)}
    domains, _ = make_variants(sketch, 4, spread)
    work = %(work)r
    variants = os.path.join(work, "variants.json")
    with open(variants, "w") as handle:
        json.dump({"name": sketch.Label, "domains": domains}, handle)
    from pathlib import Path
    run = train_dialog.TrainingRun(sketch, Path(variants), Path(work) / "model.onnx", 12, 1)
    seen = []
    started = time.time()
    while train_dialog.TrainingRun.RUNNING and time.time() - started < 200:
        QtGui.QApplication.processEvents()
        seen.append(run.dialog.value())
        time.sleep(0.05)
    result["finished"] = not train_dialog.TrainingRun.RUNNING
    result["run_error"] = run.error
    result["progress_max"] = max(seen) if seen else -1
    result["embedded"] = bool(mesh.Model)
    folder = os.environ["QUADCNN_MODELS"]
    result["saved"] = sorted(os.listdir(folder)) if os.path.isdir(folder) else []
except Exception:
    result["error"] = traceback.format_exc()
with open(%(report)r, "w") as handle:
    json.dump(result, handle)
os._exit(0)
"""


def test_train_model_runs_in_a_process_and_installs_the_model(tmp_path):
    report, work, models = tmp_path / "train.json", tmp_path / "work", tmp_path / "models"
    work.mkdir()
    design = tmp_path / "design.FCStd"
    shutil.copyfile(REPO / "resources" / "examples" / "plate_design.FCStd", design)
    script = tmp_path / "train_check.py"
    script.write_text(TRAIN_CHECK % {"design": str(design), "work": str(work),
                                     "report": str(report)})
    result = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", "freecad",
                             str(script)], capture_output=True, text=True, cwd=tmp_path,
                            env={**FREECAD_ENV, "QUADCNN_MODELS": str(models)}, timeout=400)
    assert report.is_file(), (result.stdout + result.stderr)[-3000:]
    data = json.loads(report.read_text())
    assert "error" not in data, data.get("error")
    assert data["finished"] and not data["run_error"], data["run_error"]
    assert data["progress_max"] > 300  # the bar moved with the process's progress lines
    assert data["saved"] == ["design_Plate.json", "design_Plate.onnx"]
    assert data["embedded"]
    assert not work.exists()  # the scratch folder is cleaned up
