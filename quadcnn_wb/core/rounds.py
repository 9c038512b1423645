"""Partition, segment counts and quad mesh from a set of streamlines, rebuilt in rounds
until the mesh is valid.

A layout seldom comes out right the first time on a real part: a block's map folds, a
free face cannot be filled, no segment counts balance a block.  Each round gives up
what failed (frees the folded blocks, dissolves the lines round an unfillable face,
frees the unbalanced ones) or adds lines across a fold (layout.cuts), and builds the
partition again from the same streamlines; the last resort splits the faces of six and
more corners; lenses by the rim lose their line.  Every alternative is kept only if its
mesh is better (mesh_key).  core.pipeline decides which streamlines (which background)
these rounds start from.
"""

from __future__ import annotations

import re
import time

import numpy as np

from .layout.components import Components
from .layout.cusps import tip_corners
from .layout.cuts import connecting_cuts, fold_cuts
from .layout.partition import STAR_CORNERS, build_partition, corners_instead_of_4
from .layout.partition_types import (
    FreeFaceError,
    Partition,
    PartitionError,
    block_area_share,
    free_blocks,
)
from .layout.quantize import InfeasibleCounts, quantize, quantize_freeing
from .mesh.improve import corner_jacobians
from .mesh.orientation import tiles_exactly
from .mesh.quadmesh import SquashedBlocks, build_quad_mesh, scaled_jacobians
from .mesh.quality import structured_share
from .mesh.validity import boundary_on_free_edges, crossing_quads, free_edges_on_boundary

MIN_VALID_JACOBIAN = 0.05  # a block-structured mesh worse than this is not handed out
TIP_JACOBIAN = 1e-6  # ... but a quad at a cusp's tip need only beat this: not fold, and
# not be flat to round-off (three corners on one line read 0 or 1e-17 by the pose)

FAIR_JACOBIAN = 0.2  # a worst element below this outweighs a higher structured share


def mesh_key(mesh) -> tuple:
    """What makes one mesh better than another: fair (no element below FAIR_JACOBIAN),
    then more of it in blocks, then a better worst element."""
    worst = round(float(scaled_jacobians(mesh.nodes, mesh.quads).min()), 9)
    return (worst >= FAIR_JACOBIAN, round(structured_share(mesh), 9), worst)


def fair_but_at_tips(mesh, background, size: float) -> bool:
    """No element below FAIR_JACOBIAN but quads at a cusp's tip, whose angle no layout can
    widen (layout.cusps.tip_corners): a finer layout all in blocks whose only poor quads
    sit at tips leaves the first layout nothing to win by finishing (a plate with two
    tangent horns at diameter/100: 11 s to finish a layout that lost, 0.82 in blocks)."""
    if not len(mesh.quads):
        return False
    tip = tip_corners(background, mesh.nodes, mesh.quads, size).any(axis=1)
    worst = corner_jacobians(mesh.nodes[mesh.quads]).min(axis=1)
    return bool(tip.any()) and float(worst[~tip].min(initial=1.0)) >= FAIR_JACOBIAN


class LeavesFreeFaces(Exception):
    """The first layout leaves free faces (``stop_at_free``): not worth finishing yet."""

    def __init__(self, seconds: float, traced=None):
        super().__init__("the layout leaves free faces")
        self.seconds = seconds
        self.traced = traced  # (background, field, lines, timings): what finishing reuses


UNBALANCED = "no segment counts make its opposite sides equal"
FREEING_ROUNDS = 12  # rebuilds that free folded blocks or merge an unfillable free face


def blocks_and_mesh(domain, background, field, lines, size, smoothing, timings,
                    allow_free=True, worst_allowed=MIN_VALID_JACOBIAN, stop_at_free=False,
                    finer_fills=False):
    """Partition, segment counts and the mesh, checked; PartitionError when no valid mesh
    can be had from these streamlines.  Faces that are no blocks, and blocks whose map
    gives a degenerate element, get unstructured quads (free faces); a free face that
    cannot be filled (it pinches or touches itself) loses its streamline edges, merging
    it with its neighbours, and the partition is built again.  A block whose map folds
    first gets lines across the fold (layout.cuts.fold_cuts); unless that gives a mesh
    all in blocks with no element worse than GOOD_JACOBIAN, the rounds run again
    without such lines, freeing the folded blocks instead, and the better mesh is kept
    (the lines across gave NIST CTC 01's logo bracket worse free faces, and held-out
    0016 at diameter/100 a worst element of 0.29 for 0.88).  Not when ``allow_free`` is
    False (the cnn path: its lines are then not trusted).  ``worst_allowed``: the
    scaled Jacobian a mesh must beat (lower only where the alternative is a folded
    mesh).  ``stop_at_free``: raise LeavesFreeFaces as soon as the first partition has
    free faces.  ``finer_fills``: a free face that cannot be filled is tried with its
    boundary segments split (quadmesh.build_quad_mesh) before its lines are dissolved."""
    spent = {"partition": 0.0, "quantization": 0.0, "quad_mesh": 0.0}
    cutter = FoldCutter(domain, background, field) if allow_free else None
    args = (domain, background, field, lines, size, smoothing, spent, allow_free,
            worst_allowed, stop_at_free, finer_fills)
    try:
        try:
            found, error = _blocks_and_mesh(*args, cutter), None
        except PartitionError as exc:
            if cutter is None or not cutter.used:
                raise
            found, error = None, exc
        if cutter is None or not cutter.used or \
                (found is not None and _whole_and_good(found[3])):
            return found
        try:
            plain = _blocks_and_mesh(*args, None)
        except PartitionError:
            if found is None:
                raise error from None
            return found
        return found if found is not None and mesh_key(found[3]) > mesh_key(plain[3]) \
            else plain
    finally:
        timings.update(spent)


GOOD_JACOBIAN = 0.5  # a mesh all in blocks and no worse than this is not raced


def _whole_and_good(mesh) -> bool:
    _, share, worst = mesh_key(mesh)
    return share >= 1.0 and worst >= GOOD_JACOBIAN


def _blocks_and_mesh(domain, background, field, lines, size, smoothing, timings, allow_free,
                     worst_allowed, stop_at_free, finer_fills, cutter):
    """blocks_and_mesh, with lines across folding blocks from ``cutter`` (or None)."""
    clock = time.perf_counter()
    cuts = connecting_cuts(domain, background, field, lines)  # the same in every round
    timings["partition"] += time.perf_counter() - clock
    state = {"dissolve": frozenset(), "freed": set(), "unbalanced": set(),
             "finer_fills": finer_fills, "cuts": cuts, "fold_cuts": cutter}
    found = _rounds(domain, background, lines, size, smoothing, timings, allow_free,
                    worst_allowed, stop_at_free, False, state)
    if not allow_free:
        return found
    last_resorted = False
    if any(any(why in face.reason for why in LAST_RESORT_REASONS)
           for face in found[1].free_faces):
        # Six-cornered faces that no rebuild made into blocks: cut in two; faces of more
        # corners, or with reflex ones: split round a centre (layout.subdivide), at the
        # price of irregular vertices at the cut's ends or the centre, where the faces'
        # quads are unstructured otherwise.  Kept if the mesh is better (fair, more in
        # blocks) and no less of it in blocks: blocks it could only give up again (their
        # maps fold) would leave a fair mesh by freeing what was blocks before (0073 of
        # the held-out faces: 0.70 of it in blocks, then 0.29).  The rounds go on from
        # where the first ones stopped (what they dissolved and gave up).
        try:
            cut = _rounds(domain, background, lines, size, smoothing, timings,
                          allow_free, worst_allowed, stop_at_free, True, state,
                          _to_beat(domain, found[1]))
            before, after = mesh_key(found[3]), mesh_key(cut[3])
            if after > before and after[1] >= before[1]:
                found, last_resorted = cut, True
        except PartitionError:
            pass
    lens = _lens_lines(found[1]) - state["dissolve"]
    if not lens:
        return found
    # Two-cornered faces between a line and the rim (a line from a hole's corner that
    # hugs the hole's side to the next corner): the line goes, and the face with it.
    # Kept if the mesh is better; the last resort is taken as in the mesh it must beat.
    state = dict(state, dissolve=state["dissolve"] | lens)
    try:
        merged = _rounds(domain, background, lines, size, smoothing, timings,
                         allow_free, worst_allowed, stop_at_free, last_resorted, state,
                         _to_beat(domain, found[1]))
    except PartitionError:
        return found
    return merged if mesh_key(merged[3]) > mesh_key(found[3]) else found


# In the reasons of the free faces the last resort may make into blocks.
LAST_RESORT_REASONS = tuple(corners_instead_of_4(n) for n in range(6, STAR_CORNERS + 1)) \
    + ("turns back",)
LENS = corners_instead_of_4(2)  # ... and of a two-cornered one


def _lens_lines(partition: Partition) -> frozenset:
    """The longest streamline edge round each of the partition's two-cornered free faces
    that touch the boundary (a lens between two lines is left as it is)."""
    out = set()
    for face in partition.free_faces:
        if LENS not in face.reason:
            continue
        ring = [partition.edges[e] for loop in face.rings for e, _ in loop]
        inner = [edge for edge in ring if not edge.is_boundary]
        if inner and len(inner) < len(ring):
            out.add(max(inner, key=lambda edge: (edge.length, edge.origin)).origin)
    return frozenset(out)


def _twin_lines(partition: Partition, element_size: float) -> frozenset:
    """The longer of two streamline edges that alone bound a two-cornered face no wider
    than an element: two traces that left different places and met on the same stretch
    (grabcad_part19's bosses: lenses of half an element, which kept its 2048-node layout
    from being all blocks).  Without it the face is its neighbour's; that neighbour's
    side is the other line, between the same two corners."""
    out = set()
    for face in partition.free_faces:
        if LENS not in face.reason or face.holes or len(face.halves) != 2:
            continue
        a, b = (partition.edges[e] for e, _ in face.halves)
        if a.is_boundary or b.is_boundary:
            continue
        gaps = np.hypot(*(a.points[:, None, :] - b.points[None, :, :]).transpose(2, 0, 1))
        if max(gaps.min(axis=1).max(), gaps.min(axis=0).max()) <= element_size:
            out.add(max((a, b), key=lambda edge: (edge.length, edge.origin)).origin)
    return frozenset(out)


# A rebuild that must beat a mesh in hand stops once this much less of its area is in
# blocks than the one in hand's partition: rebuilds only ever free more.
BEHIND = 0.05


def _to_beat(domain, partition: Partition) -> float:
    return block_area_share(partition, domain.area) - BEHIND


def _check_ahead(domain, partition: Partition, to_beat) -> None:
    if to_beat is not None and block_area_share(partition, domain.area) < to_beat:
        raise PartitionError("the rebuilds leave less in blocks than the mesh in hand")


def _rounds(domain, background, lines, size, smoothing, timings, allow_free,
            worst_allowed, stop_at_free, last_resort, state, to_beat=None):
    """blocks_and_mesh's partitions and rebuilds, with or without cutting hexagons;
    ``state`` holds the edges dissolved and blocks given up so far, and is updated.
    ``to_beat``: the share of the area in blocks below which the rounds give up
    (PartitionError), a try that must beat a mesh in hand and can no longer (a part's
    last resort dissolved round after round down to 0.17 in blocks, 6 of its 8 s, to
    lose to the 0.76 it had)."""
    dissolve, freed, unbalanced = state["dissolve"], set(state["freed"]), set(state["unbalanced"])
    cuts = state["cuts"]
    for round_ in range(FREEING_ROUNDS + 1):
        clock = time.perf_counter()
        partition = build_partition(domain, lines, background.element_size, cuts, dissolve,
                                    background.flat_joints, background.feature_corners,
                                    last_resort)
        twins = _twin_lines(partition, background.element_size) - dissolve
        if twins:  # one of each pair goes, before anything else is decided
            dissolve = dissolve | twins
            partition = build_partition(domain, lines, background.element_size, cuts,
                                        dissolve, background.flat_joints,
                                        background.feature_corners, last_resort)
        partition = free_blocks(partition, [k for k in range(len(partition.blocks))
                                            if _block_key(partition, k) in freed],
                                "a block map gives a degenerate element")
        timings["partition"] += time.perf_counter() - clock
        if partition.free_faces and not allow_free:
            raise PartitionError(partition.free_faces[0].reason)
        if stop_at_free and partition.free_faces:
            # Before the program: with free faces it often cannot keep every block, and
            # the one that may give blocks up is the slow one (nist_ctc04_plate: 3 s).
            raise LeavesFreeFaces(sum(timings.values()))
        clock = time.perf_counter()
        # Blocks an earlier round's counts gave up are given up before the program: the
        # one that may give blocks up is slow on a big partition (perforated_plate: 3 to
        # 10 s a solve), and the rounds would pose it again for the same blocks.
        partition = free_blocks(partition, [k for k in range(len(partition.blocks))
                                            if _block_key(partition, k) in unbalanced],
                                UNBALANCED)
        _check_ahead(domain, partition, to_beat)
        try:
            # A first layout stops as soon as some block must be given up: the program
            # that chooses which is the slow one (nist_ctc04_plate's 2048-node layout:
            # 6 s, where the finer layout is all blocks in 1.4 s).
            counts, unequal = quantize_freeing(partition, size) \
                if allow_free and not stop_at_free else (quantize(partition, size), [])
        except InfeasibleCounts:
            if not stop_at_free:
                raise
            timings["quantization"] += time.perf_counter() - clock
            raise LeavesFreeFaces(sum(timings.values())) from None
        unbalanced |= {_block_key(partition, b) for b in unequal}
        partition = free_blocks(partition, unequal, UNBALANCED)
        timings["quantization"] += time.perf_counter() - clock
        if stop_at_free and partition.free_faces:
            raise LeavesFreeFaces(sum(timings.values()))
        _check_ahead(domain, partition, to_beat)
        clock = time.perf_counter()
        try:
            mesh = build_quad_mesh(domain, partition, counts, smoothing=smoothing,
                                   finer_fills=state.get("finer_fills", False))
        except FreeFaceError as exc:
            timings["quad_mesh"] += time.perf_counter() - clock
            if not exc.origins or round_ == FREEING_ROUNDS:
                raise PartitionError(str(exc)) from None
            dissolve = dissolve | exc.origins
            continue
        except SquashedBlocks as exc:
            timings["quad_mesh"] += time.perf_counter() - clock
            if not exc.blocks or not allow_free or round_ == FREEING_ROUNDS:
                raise
            freed |= {_block_key(partition, b) for b in exc.blocks}
            continue
        timings["quad_mesh"] += time.perf_counter() - clock
        corner_sj = corner_jacobians(mesh.nodes[mesh.quads])
        # A corner at a cusp's tip is as good as the tip lets it be: it need only not fold.
        tip = tip_corners(background, mesh.nodes, mesh.quads, size)
        bad = (corner_sj <= np.where(tip, TIP_JACOBIAN, MIN_VALID_JACOBIAN)).any(axis=1)
        if not tiles_exactly(mesh.nodes, mesh.quads):
            bad |= crossing_quads(mesh.nodes, mesh.quads)  # blocks folded over others
        folded = {_block_key(partition, int(b)) for b in mesh.block_of_quad[bad] if b >= 0}
        merged = {partition.edges[e].origin
                  for f in np.unique(mesh.free_face_of_quad[bad]) if f >= 0
                  for ring in partition.free_faces[f].rings for e, _ in ring
                  if not partition.edges[e].is_boundary}
        if not (folded or merged) or not allow_free or round_ == FREEING_ROUNDS:
            break
        if folded and state["fold_cuts"] is not None:
            across = state["fold_cuts"](mesh, bad, cuts)
            if across:
                cuts = cuts + across
                continue
        freed |= folded
        dissolve = dissolve | merged
    state.update(dissolve=dissolve, freed=freed, unbalanced=unbalanced, cuts=cuts)
    if not len(corner_sj):
        worst = 0.0
    elif (corner_sj[tip] <= TIP_JACOBIAN).any():
        worst = float(corner_sj[tip].min())  # folded (or flat) at a cusp's tip
    else:
        worst = float(corner_sj[~tip].min(initial=1.0))  # tips: as good as they allow
    if worst <= worst_allowed:
        if worst > 0.0 and tiles_exactly(mesh.nodes, mesh.quads) \
                and free_edges_on_boundary(mesh.quads, mesh.boundary) \
                and boundary_on_free_edges(mesh.quads, mesh.boundary):
            raise PoorMesh(worst, (cuts, partition, counts, mesh))
        raise PartitionError(_degenerate(worst))
    if not tiles_exactly(mesh.nodes, mesh.quads):
        raise PartitionError("the blocks overlap (their quads fold over each other)")
    if not free_edges_on_boundary(mesh.quads, mesh.boundary):
        raise PartitionError("the blocks leave a gap inside the domain")
    if not boundary_on_free_edges(mesh.quads, mesh.boundary):
        raise PartitionError("the quads cover a hole")
    return cuts, partition, counts, mesh


FOLD_CUT_ROUNDS = 3  # rounds that may add lines across folding blocks (layout.cuts)


class FoldCutter:
    """Adds lines across the blocks whose maps fold (layout.cuts.fold_cuts), in at most
    FOLD_CUT_ROUNDS rounds; ``used``: whether it added any."""

    def __init__(self, domain, background, field):
        self.domain, self.background, self.field = domain, background, field
        self.rounds_left = FOLD_CUT_ROUNDS
        self.used = False

    def __call__(self, mesh, bad, cuts) -> list:
        if self.rounds_left <= 0:
            return []
        self.rounds_left -= 1
        across = fold_cuts(self.domain, self.background, self.field,
                           _fold_places(mesh, bad), list(cuts))
        self.used = self.used or bool(across)
        return across


def _fold_places(mesh, bad) -> list:
    """The middle of each group of folded quads of a block (quads sharing a node)."""
    places = []
    for b in np.unique(mesh.block_of_quad[bad]):
        if b < 0:
            continue
        picked = np.flatnonzero(bad & (mesh.block_of_quad == b))
        groups = Components()
        for q in picked:
            for n in mesh.quads[q]:
                groups.union(("quad", int(q)), ("node", int(n)))
        members: dict = {}  # root -> quads, in the order of each group's first quad
        for q in picked:
            members.setdefault(groups.find(("quad", int(q))), []).append(q)
        for quads in members.values():
            places.append(mesh.nodes[mesh.quads[quads]].reshape(-1, 2).mean(axis=0))
    return places


class PoorMesh(PartitionError):
    """A valid mesh (no element folds) whose worst element is below MIN_VALID_JACOBIAN:
    not handed out while gmsh's own quads are better, kept for where they fold."""

    def __init__(self, worst: float, result: tuple):
        super().__init__(_degenerate(worst))
        self.worst = worst
        self.result = result


def _degenerate(worst: float) -> str:
    return f"the block maps give a degenerate element (scaled Jacobian {worst:.3f})"


def _block_key(partition: Partition, b: int) -> frozenset:
    """A block named by its corner places, which a rebuild of the same input repeats
    exactly (vertex numbers may change when other edges go)."""
    return frozenset(tuple(partition.vertices[c].tolist()) for c in partition.blocks[b].corners)


def free_face_problem(partition: Partition) -> str:
    """What the result says when some faces got unstructured quads."""
    if not partition.free_faces:
        return ""
    # Without the places: one reason for all faces of a kind ("a block has 5 corners
    # instead of 4"; split at " near " it was only "a block").
    reasons = sorted({re.sub(r" near \([^)]*\)", "", face.reason)
                      for face in partition.free_faces})
    return (f"{len(partition.free_faces)} of {len(partition.free_faces) + len(partition.blocks)}"
            f" faces are no blocks ({'; '.join(reasons)}): unstructured quads there")
