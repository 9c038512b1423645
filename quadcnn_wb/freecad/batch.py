"""Regenerating many designs: every QuadCNN mesh of the open documents, or of every .FCStd
in a folder (headless), with the meshes written beside the files and a summary table.

Used by resources/macros/QuadCNN_Regenerate.FCMacro.
"""

from __future__ import annotations

import time
from pathlib import Path

import FreeCAD

from .mesh_object import QuadMeshProxy


def quad_mesh_objects(doc) -> list:
    return [o for o in doc.Objects if isinstance(getattr(o, "Proxy", None), QuadMeshProxy)]


def regenerate_document(doc, out_dir=None) -> list[dict]:
    """Recompute every QuadCNN mesh of doc; write <doc>_<object>.inp/.vtk into out_dir."""
    rows = []
    for obj in quad_mesh_objects(doc):
        started = time.perf_counter()
        obj.touch()
        doc.recompute()
        row = {"file": Path(doc.FileName).name if doc.FileName else doc.Name,
               "object": obj.Label, "quads": obj.Quads, "min_sj": obj.MinScaledJacobian,
               "method": obj.MethodUsed, "seconds": time.perf_counter() - started,
               "error": "" if obj.isValid() else obj.Status}
        if out_dir is not None and obj.isValid():
            stem = Path(out_dir) / f"{Path(doc.FileName).stem or doc.Name}_{obj.Name}"
            for suffix in (".inp", ".vtk"):
                obj.FemMesh.write(str(stem.with_suffix(suffix)))
        rows.append(row)
    return rows


def regenerate_folder(folder) -> list[dict]:
    """Open, regenerate, export and save every .FCStd in folder."""
    rows = []
    for path in sorted(Path(folder).glob("*.FCStd")):
        doc = FreeCAD.openDocument(str(path))
        try:
            rows.extend(regenerate_document(doc, out_dir=path.parent))
            doc.save()
        except Exception as exc:  # one broken file must not stop the batch
            rows.append({"file": path.name, "object": "", "quads": 0, "min_sj": 0.0,
                         "method": "", "seconds": 0.0, "error": str(exc)})
        finally:
            FreeCAD.closeDocument(doc.Name)
    return rows


def summary(rows) -> str:
    head = f"{'file':<28} {'object':<16} {'quads':>6} {'min SJ':>7} {'method':<10} " \
           f"{'time':>7}  error"
    lines = [head, "-" * len(head)]
    for r in rows:
        lines.append(f"{r['file']:<28} {r['object']:<16} {r['quads']:>6} {r['min_sj']:>7.3f} "
                     f"{r['method']:<10} {r['seconds']:>6.2f}s  {r['error']}")
    return "\n".join(lines)
