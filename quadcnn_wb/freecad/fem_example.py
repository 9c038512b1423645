"""A FreeCAD FEM analysis on a QuadCNN mesh: a 200 x 100 x 1 mm steel plate with a 20 mm
central hole pulled at 100 MPa, solved by CalculiX through FreeCAD's own ccxtools.

FreeCAD 0.20 has no plane-stress option, so the plate is a shell (S4): the left edge is
clamped (x, z and rotations), one corner is pinned in y, the right edge carries 10 kN
along x.  The peak sxx at the hole is compared with Heywood's concentration factor.
`freecadcmd -c "from quadcnn_wb.freecad.fem_example import main; main()"` builds, solves
and prints; `build(doc)` is what resources/examples/plate_tension.FCStd was saved from.
"""

from __future__ import annotations

import FreeCAD
import ObjectsFem
import Part

from ..fem.plate_tension import heywood_kt_net
from .mesh_object import make_quad_mesh

LENGTH, WIDTH, DIAMETER, TRACTION = 200.0, 100.0, 20.0, 100.0


def build(doc, size: float = 2.5):
    V = FreeCAD.Vector
    outline = Part.Face(Part.Wire(Part.makePolygon(
        [V(0, 0, 0), V(LENGTH, 0, 0), V(LENGTH, WIDTH, 0), V(0, WIDTH, 0), V(0, 0, 0)])))
    hole = Part.Face(Part.Wire(Part.makeCircle(DIAMETER / 2, V(LENGTH / 2, WIDTH / 2, 0))))
    plate = doc.addObject("Part::Feature", "Plate")
    plate.Shape = outline.cut(hole)
    doc.recompute()
    mesh = make_quad_mesh(doc, (plate, "Face1"), ElementSize=size)
    analysis = ObjectsFem.makeAnalysis(doc, "Analysis")
    solver = ObjectsFem.makeSolverCalculixCcxTools(doc, "CalculiX")
    solver.AnalysisType = "static"
    material = ObjectsFem.makeMaterialSolid(doc, "Steel")
    material.Material = {"Name": "Steel", "YoungsModulus": "210000 MPa",
                         "PoissonRatio": "0.3", "Density": "7900 kg/m^3"}
    thickness = ObjectsFem.makeElementGeometry2D(doc, 1.0, "Thickness")
    edges = {i + 1: e for i, e in enumerate(plate.Shape.Edges)}
    left = next(n for n, e in edges.items() if e.BoundBox.XMax < 1e-9)
    right = next(n for n, e in edges.items() if e.BoundBox.XMin > LENGTH - 1e-9)
    bottom = next(n for n, e in edges.items() if e.BoundBox.YMax < 1e-9)
    corner = next(i + 1 for i, v in enumerate(plate.Shape.Vertexes) if v.Point.Length < 1e-9)
    clamp = ObjectsFem.makeConstraintDisplacement(doc, "Clamp")
    clamp.References = [(plate, f"Edge{left}")]
    for axis in ("x", "z", "rotx", "roty", "rotz"):
        setattr(clamp, f"{axis}Fix", True)
        setattr(clamp, f"{axis}Free", False)
    pin = ObjectsFem.makeConstraintDisplacement(doc, "Pin")
    pin.References = [(plate, f"Vertex{corner}")]
    pin.yFix, pin.yFree = True, False
    pull = ObjectsFem.makeConstraintForce(doc, "Pull")
    pull.References = [(plate, f"Edge{right}")]
    pull.Force = TRACTION * WIDTH * 1.0
    pull.Direction = (plate, [f"Edge{bottom}"])
    for obj in (solver, material, thickness, clamp, pin, pull, mesh):
        analysis.addObject(obj)
    doc.recompute()
    return analysis


def solve(doc) -> dict:
    """Run CalculiX on the document's analysis; peak sxx at the hole against Heywood."""
    from femtools import ccxtools

    analysis = doc.getObject("Analysis")
    fea = ccxtools.FemToolsCcx(analysis, doc.getObject("CalculiX"))
    fea.update_objects()
    fea.setup_working_dir()
    fea.setup_ccx()
    problem = fea.check_prerequisites()
    if problem:
        raise RuntimeError(problem)
    fea.write_inp_file()
    fea.ccx_run()
    fea.load_results()
    result = next(o for o in doc.Objects if o.TypeId.startswith("Fem::FemResult"))
    peak = max(result.NodeStressXX)
    nominal_net = TRACTION * WIDTH / (WIDTH - DIAMETER)
    expected = heywood_kt_net(DIAMETER / WIDTH) * nominal_net
    return {"peak_sxx": peak, "expected": expected, "error": peak / expected - 1.0}


def main() -> None:
    doc = FreeCAD.newDocument("plate_tension")
    build(doc)
    r = solve(doc)
    print(f"peak sxx {r['peak_sxx']:.1f} MPa, Heywood {r['expected']:.1f} MPa "
          f"({r['error']:+.1%})")
