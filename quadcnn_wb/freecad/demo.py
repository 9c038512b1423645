# SPDX-License-Identifier: LGPL-2.1-or-later
"""The main job in headless FreeCAD, as `make demo` runs it:
`QUADCNN_OUT=out freecadcmd quadcnn_wb/freecad/demo.py`.

Opens a copy of the bundled design (resources/examples/plate_design.FCStd), puts a QuadCNN
mesh on its sketch, widens the plate by editing the "Width" constraint, regenerates, saves
the document and writes the mesh as .inp (CalculiX) and as a picture.
"""

import os
import shutil
import sys

import FreeCAD

from quadcnn_wb.core.mesh.export import write_inp
from quadcnn_wb.freecad import make_quad_mesh
from quadcnn_wb.freecad.environment import resource_path
from quadcnn_wb.viz.mesh_plot import plot_mesh

out = os.path.abspath(os.environ.get("QUADCNN_OUT", "out"))
os.makedirs(out, exist_ok=True)
design = os.path.join(out, "plate_design.FCStd")
shutil.copyfile(resource_path("examples", "plate_design.FCStd"), design)
doc = FreeCAD.openDocument(design)
sketch = doc.getObject("Plate")
mesh = make_quad_mesh(doc, sketch, ElementSize=4.0)
doc.recompute()
print(f"\nbefore the edit: {mesh.Quads} quads, min scaled Jacobian "
      f"{mesh.MinScaledJacobian:.3f}, {mesh.IrregularVertices} irregular vertices")
sketch.setDatum("Width", FreeCAD.Units.Quantity("140 mm"))
doc.recompute()
if not mesh.isValid():
    sys.exit(f"regeneration failed: {mesh.Status}")
print(f"after Width = 140 mm: {mesh.Quads} quads in {mesh.Blocks} blocks, min scaled "
      f"Jacobian {mesh.MinScaledJacobian:.3f}, {mesh.IrregularVertices} irregular vertices")
doc.save()
result = mesh.Proxy.last_result
write_inp(os.path.join(out, "plate_design_mesh.inp"), result.domain, result.mesh)
plot_mesh(result, os.path.join(out, "plate_design_mesh.png"))
print(f"wrote {design}, plate_design_mesh.inp and plate_design_mesh.png in {out}")
FreeCAD.closeDocument(doc.Name)
