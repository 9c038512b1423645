"""A plate with a central hole under tension, solved by CalculiX on a QuadCNN mesh.

The classic check of a mesh for stress analysis: the peak hoop stress at the hole must
match the stress concentration factor of a finite-width plate (Heywood's fit to Howland's
solution: Kt on the net section = 2 + (1 - d/W)^3).  Plane stress CPS4 elements, the
left edge held, a uniform traction on the right edge as consistent nodal forces; the
peak is read from the nodal stresses CalculiX extrapolates into the .frd file.
Run: `python -m quadcnn_wb.fem.plate_tension`.
"""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from ..core.input.domain import domain_from_json
from ..core.mesh.export import boundary_node_sets, write_inp
from ..core.pipeline import mesh_domain


def heywood_kt_net(d_over_w: float) -> float:
    return 2.0 + (1.0 - d_over_w) ** 3


def plate_with_hole(length: float, width: float, diameter: float):
    pts = [[0, 0], [length, 0], [length, width], [0, width]]
    outer = [{"line": [pts[i], pts[(i + 1) % 4]]} for i in range(4)]
    hole = [{"circle": {"center": [length / 2, width / 2], "radius": diameter / 2}}]
    return domain_from_json({"loops": [outer, hole]})


def solve(length=200.0, width=100.0, diameter=20.0, size=2.0, thickness=1.0,
          traction=100.0, workdir=None) -> dict:
    ccx = shutil.which("ccx")
    if ccx is None:
        raise RuntimeError("CalculiX (ccx) is not installed: apt-get install calculix-ccx")
    domain = plate_with_hole(length, width, diameter)
    result = mesh_domain(domain, size=size)
    mesh = result.mesh
    work = Path(workdir or tempfile.mkdtemp(prefix="quadcnn_ccx_"))
    deck = work / "plate.inp"
    write_inp(deck, domain, mesh)
    sets = boundary_node_sets(domain, mesh.nodes, mesh.boundary)
    left, right = sets["LOOP0_SEG3"], sets["LOOP0_SEG1"]
    forces = _edge_forces(mesh.nodes, right, axis=1, traction=traction * thickness)
    corner = min(left, key=lambda n: mesh.nodes[n][1])
    with open(deck, "a", encoding="ascii") as f:
        f.write("*MATERIAL, NAME=STEEL\n*ELASTIC\n210000, 0.3\n")
        f.write(f"*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n{thickness}\n")
        f.write("*STEP\n*STATIC\n*BOUNDARY\n")
        for n in left:
            f.write(f"{n + 1}, 1, 1, 0.0\n")
        f.write(f"{corner + 1}, 2, 2, 0.0\n")
        f.write("*CLOAD\n")
        for n, force in forces.items():
            f.write(f"{n + 1}, 1, {force:.12g}\n")
        f.write("*NODE FILE\nS\n*END STEP\n")
    run = subprocess.run([ccx, "-i", "plate"], cwd=work, capture_output=True, text=True,
                         timeout=300)
    if run.returncode != 0 or not (work / "plate.frd").is_file():
        raise RuntimeError(f"CalculiX failed: {run.stdout[-500:]}")
    stress = _frd_stress(work / "plate.frd")
    peak = max(stress[n + 1][0] for n in sets["LOOP1"])
    d_over_w = diameter / width
    nominal_net = traction * width / (width - diameter)
    expected = heywood_kt_net(d_over_w) * nominal_net
    return {"quads": len(mesh.quads), "peak_sxx": peak, "expected": expected,
            "error": peak / expected - 1.0, "kt_net": peak / nominal_net, "workdir": str(work),
            "min_scaled_jacobian": result.quality["min_scaled_jacobian"]}


def _edge_forces(nodes, ids, axis: int, traction: float) -> dict:
    """Consistent nodal forces of a uniform traction along a straight edge of nodes."""
    order = sorted(ids, key=lambda n: nodes[n][axis])
    forces = dict.fromkeys(order, 0.0)
    for a, b in zip(order[:-1], order[1:]):
        half = 0.5 * traction * float(np.hypot(*(nodes[b] - nodes[a])))
        forces[a] += half
        forces[b] += half
    return forces


def _frd_stress(path) -> dict:
    """Node id -> (sxx, syy, szz, sxy, syz, szx) from the STRESS block of a .frd file."""
    out, inside = {}, False
    for line in Path(path).read_text(errors="replace").splitlines():
        if line.startswith(" -4  STRESS"):
            inside = True
            continue
        if inside:
            if line.startswith(" -3"):
                break
            if line.startswith(" -1"):
                node = int(line[3:13])
                values = [float(line[13 + 12 * k: 25 + 12 * k]) for k in range(6)]
                out[node] = tuple(values)
    return out


def main() -> int:
    r = solve()
    print(f"plate 200 x 100 mm, hole 20 mm, {r['quads']} quads (min scaled Jacobian "
          f"{r['min_scaled_jacobian']:.3f}): peak sxx {r['peak_sxx']:.1f} MPa at the hole, "
          f"Heywood {r['expected']:.1f} MPa ({r['error']:+.1%}); Kt(net) {r['kt_net']:.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
