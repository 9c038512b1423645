"""Real FreeCAD: the headless test module through `freecadcmd -t`, the GUI under Xvfb."""

from __future__ import annotations

import json
import os
import shutil
import subprocess

from conftest import REPO

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
import json, os
import FreeCADGui
result = {}
try:
    result["listed"] = "QuadCNNWorkbench" in FreeCADGui.listWorkbenches()
    FreeCADGui.activateWorkbench("QuadCNNWorkbench")
    result["active"] = FreeCADGui.activeWorkbench().name()
    result["menu_text"] = FreeCADGui.activeWorkbench().MenuText
except Exception as exc:
    result["error"] = repr(exc)
with open(%r, "w") as handle:
    json.dump(result, handle)
os._exit(0)
"""


def test_workbench_activates_in_the_gui_under_xvfb(tmp_path):
    report = tmp_path / "gui.json"
    script = tmp_path / "gui_check.py"
    script.write_text(GUI_CHECK % str(report))
    result = subprocess.run(["xvfb-run", "-a", "freecad", str(script)], capture_output=True,
                            text=True, cwd=tmp_path, env=FREECAD_ENV, timeout=300)
    assert report.is_file(), (result.stdout + result.stderr)[-3000:]
    data = json.loads(report.read_text())
    assert data == {"listed": True, "active": "QuadCNNWorkbench", "menu_text": "QuadCNN"}, data


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
