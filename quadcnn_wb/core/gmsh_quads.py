"""Last-resort all-quad mesh from gmsh (frontal quads + blossom recombination + one
subdivision) for the rare domain whose streamlines do not give four-sided blocks.

The product promise is a valid mesh for every valid input; when the block partition
cannot be built, this one is valid but not block-structured, and the result says so.
"""

from __future__ import annotations

import gmsh
import numpy as np

from .background import _build_geometry
from .gmsh_session import gmsh_session
from .pose import canonical_pose
from .quadmesh import QuadMesh, _counter_clockwise, smooth


def gmsh_quad_mesh(domain, size: float) -> QuadMesh:
    pose = canonical_pose(domain)
    scale = pose.scale
    with gmsh_session() as session:
        curve_tags = _build_geometry(domain, pose)
        for name, value in (("Mesh.Algorithm", 8), ("Mesh.RecombineAll", 1),
                            ("Mesh.RecombinationAlgorithm", 1),
                            ("Mesh.SubdivisionAlgorithm", 1),
                            ("Mesh.MeshSizeMin", 2 * size / scale),
                            ("Mesh.MeshSizeMax", 2 * size / scale),
                            ("Mesh.MeshSizeFromPoints", 0), ("Mesh.MeshSizeFromCurvature", 0)):
            session.set(name, value)
        gmsh.model.mesh.generate(2)
        nodes, quads, index = read_quads()
        nodes = pose.from_unit(nodes)
        boundary = np.zeros(len(nodes), dtype=bool)
        for tag, (li, si) in curve_tags.items():
            btags, _, _ = gmsh.model.mesh.getNodes(1, tag, includeBoundary=True)
            ids = [index[int(t)] for t in btags]
            boundary[ids] = True
            curve = domain.loops[li][si]
            for k in ids:  # exactly on the true curve
                nodes[k] = curve.point(curve.project(nodes[k]))
    used = np.unique(quads)
    remap = np.full(len(nodes), -1)
    remap[used] = np.arange(len(used))
    nodes, boundary, quads = nodes[used], boundary[used], remap[quads]
    quads = _counter_clockwise(nodes, quads)
    nodes = smooth(nodes, quads, boundary)
    return QuadMesh(nodes=nodes, quads=quads, block_of_quad=np.zeros(len(quads), dtype=np.int64),
                    boundary=boundary, edge_nodes=())


def read_quads():
    """(nodes (N, 2), quads (Q, 4), gmsh tag -> row) of the current gmsh model's mesh."""
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    index = {int(t): k for k, t in enumerate(tags)}
    quads = []
    for _, tag in gmsh.model.getEntities(2):
        types, _, node_tags = gmsh.model.mesh.getElements(2, tag)
        for etype, nt in zip(types, node_tags):
            if etype == 3:  # 4-node quadrangle
                quads.append(np.array([index[int(t)] for t in nt]).reshape(-1, 4))
    quads = np.concatenate(quads) if quads else np.zeros((0, 4), dtype=np.int64)
    return xyz.reshape(-1, 3)[:, :2].copy(), quads, index
