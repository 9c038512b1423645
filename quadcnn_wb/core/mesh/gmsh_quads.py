"""gmsh's own quad meshes: the last resort when no block partition can be had, and the
peer every benchmark measures against.

The product promise is a valid mesh for every valid input, and never one worse than
gmsh's own on the same face, so the stand-in is gmsh's quasi-structured algorithm (11) at
the same element size: the very mesh a user would get from gmsh directly.  (Algorithm 11
splits each triangle of its size field into quads of half its edge, so elements of edge
H take a gmsh size of 2 H: QUASI_STRUCTURED_SIZE_FACTOR.)  Should it
fail (it needs a cross field of its own), frontal quads with blossom recombination and
one subdivision stand in for it.  The result is valid but not block-structured, and the
pipeline says so.
"""

from __future__ import annotations

import time

import gmsh
import numpy as np

from ..gmsh_geometry import build_geometry
from ..gmsh_session import gmsh_session, silenced_stdio
from ..input.pose import Pose, canonical_pose
from .orientation import counter_clockwise_quads
from .quadmesh import QuadMesh
from .quality import min_scaled_jacobian

QUASI_STRUCTURED = 11  # gmsh's Mesh.Algorithm for quasi-structured quads
QUASI_STRUCTURED_SIZE_FACTOR = 2.0  # gmsh size giving algorithm 11 elements of edge 1


def gmsh_quad_mesh(domain, size: float) -> QuadMesh:
    """All-quad mesh of the whole domain from gmsh, in the domain's canonical pose (so a
    turned or moved copy gets the same mesh); boundary nodes sit on the exact curves."""
    pose = canonical_pose(domain)
    try:
        mesh = _gmsh_mesh(domain, pose, _quasi_structured_options(
            QUASI_STRUCTURED_SIZE_FACTOR * size / pose.scale))
    except Exception:  # gmsh reports every failure as a bare Exception
        mesh = None
    if mesh is None or not len(mesh.quads) or min_scaled_jacobian(mesh) <= 0.0:
        mesh = _gmsh_mesh(domain, pose, _recombined_options(size / pose.scale))
    return mesh


def gmsh_quasi_structured(domain, size: float):
    """(nodes, quads, boundary mask, seconds) of gmsh's algorithm 11 on the domain as
    given, at gmsh mesh size ``size`` (elements of about size / 2): the peer of the
    benchmarks, timed on gmsh's meshing call alone."""
    with gmsh_session() as session:
        build_geometry(domain, Pose(np.zeros(2), 1.0, np.eye(2)))  # as given
        for name, value in _quasi_structured_options(size):
            session.set(name, value)
        start = time.perf_counter()
        gmsh.model.mesh.generate(2)
        seconds = time.perf_counter() - start
        nodes, quads, index = read_quads()
        boundary = np.zeros(len(nodes), dtype=bool)
        for _, tag in gmsh.model.getEntities(1):
            btags, _, _ = gmsh.model.mesh.getNodes(1, tag, includeBoundary=True)
            boundary[[index[int(t)] for t in btags]] = True
    return nodes, quads, boundary, seconds


def _quasi_structured_options(size: float) -> tuple:
    return (("Mesh.Algorithm", QUASI_STRUCTURED), ("Mesh.MeshSizeMin", size),
            ("Mesh.MeshSizeMax", size), ("Mesh.MeshSizeFromPoints", 0),
            ("Mesh.MeshSizeFromCurvature", 0))


def _recombined_options(size: float) -> tuple:
    # Subdivision halves every edge: ask for twice the size.
    return (("Mesh.Algorithm", 8), ("Mesh.RecombineAll", 1),
            ("Mesh.RecombinationAlgorithm", 1), ("Mesh.SubdivisionAlgorithm", 1),
            ("Mesh.MeshSizeMin", 2 * size), ("Mesh.MeshSizeMax", 2 * size),
            ("Mesh.MeshSizeFromPoints", 0), ("Mesh.MeshSizeFromCurvature", 0))


def _gmsh_mesh(domain, pose, options) -> QuadMesh:
    with gmsh_session() as session:
        curve_tags = build_geometry(domain, pose)
        for name, value in options:
            session.set(name, value)
        with silenced_stdio():
            gmsh.model.mesh.generate(2)
        nodes, quads, index = read_quads()
        if not len(quads) or _has_triangles():
            return None
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
    quads = counter_clockwise_quads(nodes, quads)
    return QuadMesh(nodes=nodes, quads=quads, block_of_quad=np.full(len(quads), -1),
                    boundary=boundary, edge_nodes=())


def _has_triangles() -> bool:
    for _, tag in gmsh.model.getEntities(2):
        types, _, _ = gmsh.model.mesh.getElements(2, tag)
        if 2 in list(types):
            return True
    return False


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
