"""Which mesh nodes become one when segment counts are zero.

An arc of the T-mesh with no segments has its two ends in one place; a block whose two
opposite sides have no segments is a strip of no width, so its other two sides are one
mesh line, node for node.  That is how separatrices running side by side become one mesh
line and thin strips vanish.  It must never pinch the domain: two boundary nodes, a
boundary node and a singular point, or two singular points in one place are a conflict,
reported with the merges that caused it, so that the segment-count program can forbid
one of them (quantize.py) and the mesh builder never meets one.  Nor may it carry a
vertex most of an element away (SLIDE_SPAN): chains of short arcs with no segments add up.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .components import Components


@dataclass
class NodeLayout:
    """Raw node ids: partition vertices first, then each edge's inner nodes."""

    edge_nodes: list  # per edge, node ids from vertex a to vertex b (count + 1 of them)
    n_nodes: int
    boundary: np.ndarray  # raw node on the domain boundary
    anchor: np.ndarray  # raw node that may not share a place with another anchor
    fixed: np.ndarray  # raw node at a boundary corner or a singular point
    along_boundary: Components  # raw nodes joined by no-segment boundary arcs
    places: np.ndarray  # (partition vertices, 2): where the raw nodes that are vertices lie
    longest_slide: float  # farthest apart two partition vertices may merge into one place


def node_layout(partition, counts, size: float | None = None) -> NodeLayout:
    """``size``: the target element size; partition vertices further apart than
    SLIDE_SPAN of it may not merge into one place (none: any merge, as the mesh builder
    takes the counts the program gave)."""
    n = len(partition.vertices)
    edge_nodes = []
    boundary_ids = []
    for e, edge in enumerate(partition.edges):
        k = int(counts[e])
        inner = np.arange(n, n + max(k - 1, 0))
        n += len(inner)
        ids = np.concatenate([[edge.a], inner, [edge.b]]).astype(np.int64)
        edge_nodes.append(ids)
        if edge.is_boundary:
            boundary_ids.append(ids)
    boundary = np.zeros(n, dtype=bool)
    if boundary_ids:
        boundary[np.concatenate(boundary_ids)] = True
    anchor = boundary.copy()
    anchor[list(partition.singular)] = True
    fixed = np.zeros(n, dtype=bool)
    fixed[list(partition.singular) + list(partition.fixed)] = True
    along = Components()
    for e, edge in enumerate(partition.edges):
        if edge.is_boundary and int(counts[e]) == 0:
            along.union(int(edge.a), int(edge.b))
    return NodeLayout(edge_nodes, n, boundary, anchor, fixed, along,
                      np.asarray(partition.vertices, dtype=float).reshape(-1, 2),
                      np.inf if size is None else SLIDE_SPAN * size)


# A chain of arcs with no segments (and strips of no width) puts every vertex on it in
# one place: a few short arcs between T-junctions along a boss's side added up to most of
# an element (grabcad_part19's 2048-node layout at its default size: a block corner moved
# 4.6 mm of a 5 mm element down the side, and the blocks beside it folded).
SLIDE_SPAN = 0.9


def side_nodes(layout: NodeLayout, counts, side) -> np.ndarray:
    """Raw node ids along a block side: one per segment end (zero-count arcs add none;
    the first node of each of side_places' groups)."""
    return np.array([group[0] for group in side_places(layout, counts, side)], dtype=np.int64)


def side_places(layout: NodeLayout, counts, side) -> list:
    """Raw node ids along a block side, one group per segment end: the vertices that
    no-segment arcs of the side join are one group (they share a place)."""
    first_e, first_fwd = side[0]
    groups = [[int(layout.edge_nodes[first_e][0 if first_fwd else -1])]]
    for e, forward in side:
        part = layout.edge_nodes[e] if forward else layout.edge_nodes[e][::-1]
        if int(counts[e]) == 0:
            groups[-1].append(int(part[-1]))
            continue
        groups.extend([int(i)] for i in part[1:])
    return groups


def _joining(here, there) -> list:
    """Links that put two places (groups of raw nodes) in one: each node of one group to
    the first of the other.  A collapsed strip joins the places, whole: which vertex of a
    run of no-segment arcs stood for the run depended on the direction the side was
    walked in, and with it the merges a conflict row names (a mirror image walks every
    block the other way: four_hole member 21's mirror image got rows of other arcs, and
    other counts)."""
    return [(here[0], v) for v in there] + [(u, there[0]) for u in here[1:]]


@dataclass
class Merges:
    parent: np.ndarray  # canonical raw id of every raw node
    links: list  # (u, v, reason): reason ("edge", e) or ("block", b, pair)
    collapsed: set  # blocks of no area


def merges(partition, layout: NodeLayout, counts) -> Merges:
    parent = np.arange(layout.n_nodes)

    def find(x):
        root = x
        while parent[root] != root:
            root = parent[root]
        while parent[x] != root:
            parent[x], x = root, parent[x]
        return root

    links = []
    for e, edge in enumerate(partition.edges):
        if int(counts[e]) == 0:
            links.append((int(edge.a), int(edge.b), ("edge", e)))
    collapsed = set()
    for b, block in enumerate(partition.blocks):
        sides = [side_places(layout, counts, side) for side in block.sides]
        for pair in (0, 1):
            if len(sides[pair]) == 1:  # no segments across: the other two sides are one
                collapsed.add(b)
                other, opposite = sides[pair + 1], sides[(pair + 3) % 4][::-1]
                if len(other) != len(opposite):
                    continue  # unequal sides: the counts are not a solution; caught later
                for here, there in zip(other, opposite):
                    links.extend((u, v, ("block", b, pair)) for u, v in _joining(here, there)
                                 if u != v)
    for u, v, _ in links:
        ru, rv = find(u), find(v)
        if ru != rv:
            parent[max(ru, rv)] = min(ru, rv)
    for x in range(layout.n_nodes):
        find(x)
    return Merges(parent, links, collapsed)


def conflicts(layout: NodeLayout, found: Merges, key=None) -> list:
    """For every place where two anchors were merged, merges that together pinch it: a
    least set, found in the order of ``key``.

    ``key`` (reason -> sortable, the same for a turned or mirrored copy of the part):
    reasons are taken in that order until anchors are merged, then dropped from the last
    while they still are, so that the program is refused the same merges in every pose.
    (A search along the links met equally short paths through different strips in the
    order of the pose's raw node numbers: nist_ctc04_plate's mirror image got other
    counts.)"""
    key = key or (lambda reason: reason)
    out = []
    groups: dict = {}
    for x in np.nonzero(layout.anchor)[0]:
        groups.setdefault(int(found.parent[x]), []).append(int(x))
    links_of = _links_by_place(found)
    for root in sorted(groups):
        anchors = groups[root]
        if len(anchors) < 2 or _slid(layout, anchors):
            continue
        out.append(_least_reasons(layout, links_of.get(root, []), anchors, key, _pinches))
    return out


def stretches(layout: NodeLayout, found: Merges, key=None) -> list:
    """For every place where partition vertices further apart than the longest slide
    were merged (and no anchors pinched), merges that together stretch it: a least set,
    found in the order of ``key`` (as conflicts)."""
    if not np.isfinite(layout.longest_slide):
        return []
    key = key or (lambda reason: reason)
    links_of = _links_by_place(found)
    vertices: dict = {}
    for x in range(len(layout.places)):
        vertices.setdefault(int(found.parent[x]), []).append(x)
    out = []
    for root in sorted(vertices):
        members = vertices[root]
        if not layout.anchor[members].any():
            continue  # interior vertices meet half-way, as side-by-side lines should
        if len(members) > 1 and _span(layout, members) > layout.longest_slide:
            out.append(_least_reasons(layout, links_of.get(root, []), members, key,
                                      _stretches))
    return out


def _links_by_place(found: Merges) -> dict:
    """The merge links, by the place (canonical raw id) they merge into."""
    out: dict = {}
    for u, v, reason in found.links:
        out.setdefault(int(found.parent[u]), []).append((u, v, reason))
    return out


def _least_reasons(layout, links, members, key, test) -> list:
    reasons = sorted({reason for _, _, reason in links}, key=key)
    chosen = []
    for reason in reasons:
        chosen.append(reason)
        if test(layout, links, members, set(chosen)):
            break
    for reason in reversed(list(chosen)):
        rest = set(chosen) - {reason}
        if test(layout, links, members, rest):
            chosen.remove(reason)
    return chosen


def _pinches(layout, links, anchors, reasons) -> bool:
    """Whether the links of these reasons alone put anchors together (other than a
    slide along the boundary)."""
    return any(len(group) > 1 and not _slid(layout, group)
               for group in _together(links, anchors, reasons))


def _slid(layout: NodeLayout, anchors) -> bool:
    """Anchors merged only along boundary arcs with no segments, at most one a corner."""
    return (len({layout.along_boundary.find(int(x)) for x in anchors}) == 1
            and all(layout.boundary[x] for x in anchors)
            and sum(bool(layout.fixed[x]) for x in anchors) <= 1)


def _stretches(layout: NodeLayout, links, members, reasons) -> bool:
    """Whether the links of these reasons alone put two partition vertices further apart
    than the longest slide in one place."""
    return any(len(group) > 1 and _span(layout, group) > layout.longest_slide
               for group in _together(links, members, reasons))


def _together(links, members, reasons) -> list:
    """The members in groups, one per place the links of these reasons alone make."""
    parts = Components()
    for u, v, reason in links:
        if reason in reasons:
            parts.union(u, v)
    groups: dict = {}
    for m in members:
        groups.setdefault(parts.find(m), []).append(m)
    return list(groups.values())


def _span(layout: NodeLayout, vertices) -> float:
    xy = layout.places[list(vertices)]
    return float(np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1)).max())
