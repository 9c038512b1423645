"""Turning a pipeline result into FreeCAD data: the FemMesh with its groups, and the
companion shapes (streamlines as B-spline wires, blocks as faces), all in global
coordinates through the source's placement."""

from __future__ import annotations

import Fem
import Part

from ..core.mesh.export import boundary_node_sets
from .geometry import to_global


def fem_mesh(result, placement):
    """4-node quad faces; a face group per block and a node group per boundary loop/curve."""
    mesh = result.mesh
    fm = Fem.FemMesh()
    for i, p in enumerate(to_global(placement, mesh.nodes), start=1):
        fm.addNode(p.x, p.y, p.z, i)
    for j, quad in enumerate(mesh.quads, start=1):
        fm.addFace([int(n) + 1 for n in quad], j)
    for b in sorted(set(int(b) for b in mesh.block_of_quad)):
        group = fm.addGroup(f"Block{b}" if b >= 0 else "Unstructured", "Face")
        fm.addGroupElements(group, [j + 1 for j, owner in enumerate(mesh.block_of_quad)
                                    if owner == b])
    for name, ids in boundary_node_sets(result.domain, mesh.nodes, mesh.boundary).items():
        group = fm.addGroup(name, "Node")
        fm.addGroupElements(group, [int(i) + 1 for i in ids])
    return fm


def streamline_shape(result, placement):
    edges = []
    for line in result.streamlines:
        points = to_global(placement, line.points[:: max(1, len(line.points) // 60)].tolist()
                           + [line.points[-1].tolist()])
        unique = [p for k, p in enumerate(points) if k == 0 or (p - points[k - 1]).Length > 0]
        if len(unique) < 2:
            continue
        curve = Part.BSplineCurve()
        curve.interpolate(unique)
        edges.append(curve.toShape())
    return Part.makeCompound(edges)


def block_shape(result, placement):
    faces = []
    partition = result.partition
    for block in partition.blocks:
        points = []
        for side in block.sides:
            for e, forward in side:
                pts = partition.edge_points(e, forward)
                points.extend(pts[:-1].tolist())
        wire = Part.makePolygon(to_global(placement, points + [points[0]]))
        faces.append(Part.Face(wire))
    return Part.makeCompound(faces)


def update_companions(obj, result, placement) -> None:
    """Refresh the companion shapes; they are outputs, so they must not stay touched."""
    for companion, shape in ((obj.StreamlineWires, streamline_shape),
                             (obj.BlockFaces, block_shape)):
        if companion is not None:
            companion.Shape = shape(result, placement)
            companion.purgeTouched()
