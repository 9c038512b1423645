"""Writing the quad mesh: DESIGN.md JSON, gmsh .msh, VTK, and CalculiX/Abaqus .inp.

.msh and .vtk go through meshio.  The .inp is written here because a FEM user needs more
than meshio gives: CPS4 (plane stress) elements, an element set per block and a node set
per boundary loop and per boundary curve, so loads and supports can be put on them.
Every file is written to a temporary name and moved into place (core.atomic).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..atomic import write_atomic, write_json_atomic

FORMATS = {".json", ".msh", ".vtk", ".inp"}


def boundary_node_sets(domain, nodes, boundary) -> dict:
    """Set name -> sorted node ids: LOOP<i> and LOOP<i>_SEG<j> for every boundary curve."""
    ids = np.nonzero(boundary)[0]
    tol = 1e-7 * domain.size
    sets: dict = {}
    for li, loop in enumerate(domain.loops):
        for si, curve in enumerate(loop):
            on = [int(n) for n in ids
                  if np.hypot(*(curve.point(curve.project(nodes[n])) - nodes[n])) <= tol]
            if on:
                sets[f"LOOP{li}_SEG{si}"] = sorted(on)
                sets.setdefault(f"LOOP{li}", set()).update(on)
    return {k: sorted(v) for k, v in sets.items()}


def write_inp(path, domain, mesh, element_type: str = "CPS4") -> None:
    def write(tmp):
        with open(tmp, "w", encoding="ascii") as f:
            f.write("*HEADING\nQuadCNN block-structured quadrilateral mesh\n")
            f.write("*NODE, NSET=NALL\n")
            for i, (x, y) in enumerate(mesh.nodes, start=1):
                f.write(f"{i}, {x:.17g}, {y:.17g}\n")
            f.write(f"*ELEMENT, TYPE={element_type}, ELSET=EALL\n")
            for i, q in enumerate(mesh.quads + 1, start=1):
                f.write(f"{i}, {q[0]}, {q[1]}, {q[2]}, {q[3]}\n")
            for b in np.unique(mesh.block_of_quad):
                name = f"BLOCK{b}" if b >= 0 else "UNSTRUCTURED"  # quads in no block
                _write_set(f, "ELSET", name, np.nonzero(mesh.block_of_quad == b)[0] + 1)
            for name, ids in boundary_node_sets(domain, mesh.nodes, mesh.boundary).items():
                _write_set(f, "NSET", name, np.asarray(ids) + 1)

    write_atomic(path, write)


def _write_set(f, kind: str, name: str, ids) -> None:
    f.write(f"*{kind}, {kind}={name}\n")
    ids = list(ids)
    for k in range(0, len(ids), 16):
        f.write(", ".join(str(int(i)) for i in ids[k:k + 16]) + "\n")


def write_meshio(path, mesh, file_format: str) -> None:
    import meshio

    points = np.column_stack([mesh.nodes, np.zeros(len(mesh.nodes))])
    cell_data = {"block": [mesh.block_of_quad.astype(np.int32)]}
    if file_format.startswith("gmsh"):
        tag = (mesh.block_of_quad + 1).astype(np.int32)
        cell_data = {"gmsh:physical": [np.ones_like(tag)], "gmsh:geometrical": [tag]}
    out = meshio.Mesh(points, [("quad", mesh.quads.astype(np.int64))], cell_data=cell_data)
    write_atomic(path, lambda tmp: meshio.write(tmp, out, file_format=file_format,
                                                **({"binary": False}
                                                   if file_format.startswith("gmsh") else {})))


def export(result, path) -> None:
    """Write the mesh of a MeshResult in the format the file name asks for."""
    suffix = Path(path).suffix.lower()
    if suffix == ".json":
        write_json_atomic(path, result.to_json())
    elif suffix == ".msh":
        write_meshio(path, result.mesh, "gmsh22")
    elif suffix == ".vtk":
        write_meshio(path, result.mesh, "vtk")
    elif suffix == ".inp":
        write_inp(path, result.domain, result.mesh)
    else:
        raise ValueError(f"{path}: unknown mesh format (use {', '.join(sorted(FORMATS))})")
