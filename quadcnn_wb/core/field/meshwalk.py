"""Point location on the background mesh by walking from a nearby triangle, many at once.

Streamlines advance a fraction of an element per step, so the triangle holding the next
point is the current one or a close neighbour: walking across the edge with the most
negative barycentric coordinate finds it in a step or two, vectorised over all active
streamlines.  Walking out through a boundary edge is how a streamline learns that it
has left the domain, and through which edge.
"""

from __future__ import annotations

import numpy as np

MAX_WALK = 64
INSIDE_TOL = 1e-10  # a point this near (of the mesh's extent) a triangle's side is in it:
# a hundred times the layout frame's rounding (layout_frame.FRAME_DIGITS), so a trace that
# runs along a boundary edge (a slot's tip read as one corner sends lines along its short
# side) is inside in every copy of the part, not inside or out by a last bit (held-out
# 0043: one end of such a side rounded 1e-12 off the other's x, and a turned copy lost
# the line)


def triangle_neighbours(triangles: np.ndarray) -> np.ndarray:
    """(T, 3): the triangle across the edge opposite each vertex, -1 on the boundary."""
    t = len(triangles)
    edges = np.concatenate([triangles[:, [1, 2]], triangles[:, [2, 0]], triangles[:, [0, 1]]])
    owner = np.tile(np.arange(t), 3)
    slot = np.repeat(np.arange(3), t)
    key = np.sort(edges, axis=1)
    order = np.lexsort((key[:, 1], key[:, 0]))
    key, owner, slot = key[order], owner[order], slot[order]
    same = np.all(key[1:] == key[:-1], axis=1)
    out = np.full((t, 3), -1, dtype=np.int64)
    first = np.nonzero(same)[0]
    out[owner[first], slot[first]] = owner[first + 1]
    out[owner[first + 1], slot[first + 1]] = owner[first]
    return out


class MeshWalker:
    def __init__(self, nodes: np.ndarray, triangles: np.ndarray):
        self.nodes = nodes
        self.triangles = triangles
        self.neighbours = triangle_neighbours(triangles)
        a, b, c = (nodes[triangles[:, k]] for k in range(3))
        self.origin = a
        # Inverse of the 2x2 matrix with the edge vectors as columns, in closed form
        # (np.linalg.inv on thousands of tiny matrices costs more than the whole walk).
        e1, e2 = b - a, c - a
        det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
        # Barycentric coordinate k is the distance from the side opposite vertex k over
        # that vertex's height: the tolerance per coordinate is INSIDE_TOL over it.
        sides = np.stack([np.hypot(*(c - b).T), np.hypot(*(c - a).T), np.hypot(*(b - a).T)],
                         axis=1)
        extent = float(np.hypot(*np.ptp(nodes, axis=0))) if len(nodes) else 1.0
        self.inside_tol = INSIDE_TOL * extent * sides / np.abs(det)[:, None]
        self.inverse = np.stack([np.stack([e2[:, 1], -e2[:, 0]], axis=1),
                                 np.stack([-e1[:, 1], e1[:, 0]], axis=1)], axis=1) / det[:, None,
                                                                                         None]

    def barycentric(self, tri: np.ndarray, p: np.ndarray) -> np.ndarray:
        uv = np.einsum("nij,nj->ni", self.inverse[tri], p - self.origin[tri])
        out = np.empty((len(uv), 3))  # (filled in place: column_stack costs more than the
        out[:, 0] = 1.0 - uv.sum(axis=1)  # arithmetic on a walk's few points)
        out[:, 1:] = uv
        return out

    def locate(self, tri: np.ndarray, p: np.ndarray):
        """Walk from ``tri`` to the triangle holding each point (within INSIDE_TOL).

        Returns (triangle, barycentric, exit_edge): triangle is -1 for a point that was
        walked out of the domain, and exit_edge then holds (triangle, local edge) of the
        boundary edge crossed; otherwise exit_edge is (-1, -1).
        """
        tri = np.array(tri, dtype=np.int64)
        bary = np.zeros((len(p), 3))
        exit_edge = np.full((len(p), 2), -1, dtype=np.int64)
        active = np.arange(len(p))
        for _ in range(MAX_WALK):
            if not len(active):
                break
            b = self.barycentric(tri[active], p[active])
            inside = (b >= -self.inside_tol[tri[active]]).all(axis=1)
            worst = np.argmin(b, axis=1)
            bary[active[inside]] = b[inside]
            moving = active[~inside]
            edge = worst[~inside]
            nxt = self.neighbours[tri[moving], edge]
            out = nxt < 0
            if out.any():
                exit_edge[moving[out], 0] = tri[moving[out]]
                exit_edge[moving[out], 1] = edge[out]
                tri[moving[out]] = -1
            tri[moving[~out]] = nxt[~out]
            active = moving[~out]
        tri[active] = -1  # lost (should not happen for short steps)
        return tri, bary, exit_edge
