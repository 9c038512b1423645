"""Domain to block-structured quad mesh in one call; the command line and FreeCAD use this.

The result carries every stage (background mesh, field, streamlines, partition, segment
counts, quad mesh, quality) and the time each took, so callers can draw or export any of
them without recomputing.
"""

from __future__ import annotations

import dataclasses
import re
import time
from dataclasses import dataclass, field

import numpy as np

from .field.pairs import without_cancelling_pairs
from .field.reference import Reference, background_and_field
from .input.domain import Domain
from .input.features import boundary_features
from .input.pose import default_size
from .input.small_holes import SQUARED_RESCUE, is_quartered, squared_holes
from .layout.components import Components
from .layout.cusps import tip_corners, with_cusp_kites
from .layout.cuts import connecting_cuts, fold_cuts
from .layout.lenses import without_short_lenses
from .layout.motorcycle import stop_at_first_hits
from .layout.partition import STAR_CORNERS, build_partition, corners_instead_of_4
from .layout.partition_types import (
    FreeFaceError,
    Partition,
    PartitionError,
    block_area_share,
    free_blocks,
)
from .layout.quantize import InfeasibleCounts, quantize, quantize_freeing
from .layout.tracing import trace_streamlines
from .layout.wedges import without_corner_wedges
from .layout_frame import (
    frame_of,
    framed_domain,
    framed_line,
    framed_size,
    same_frame,
    world_background,
    world_domain,
    world_field,
    world_result,
)
from .mesh.gmsh_quads import gmsh_quad_mesh
from .mesh.improve import corner_jacobians
from .mesh.orientation import tiles_exactly
from .mesh.quadmesh import QuadMesh, SquashedBlocks, build_quad_mesh, scaled_jacobians
from .mesh.quality import mesh_quality, structured_share

MIN_VALID_JACOBIAN = 0.05  # a block-structured mesh worse than this is not handed out
TIP_JACOBIAN = 1e-6  # ... but a quad at a cusp's tip need only beat this: not fold, and
# not be flat to round-off (three corners on one line read 0 or 1e-17 by the pose)


@dataclass
class MeshResult:
    domain: Domain
    reference: Reference
    cuts: list
    partition: Partition
    counts: np.ndarray
    mesh: QuadMesh
    quality: dict
    size: float
    method: str = "numerical"
    fallback: list = field(default_factory=list)
    structured: bool = True  # False: no block partition; gmsh's quad mesh stands in
    problem: str = ""  # why the mesh is not block-structured
    timings: dict = field(default_factory=dict)

    @property
    def structured_share(self) -> float:
        """Share of the quads that lie in blocks: 1.0 for a fully block-structured mesh."""
        return structured_share(self.mesh)

    @property
    def feature_corners(self) -> int:
        """Corners the layout reads where the boundary is smooth (small concave fillets,
        small round holes' squares: input.features), each a node DESIGN.md counts as
        irregular beside the field's singular points."""
        return sum(f.angle is not None
                   for f in boundary_features(self.reference.domain, self.size))

    @property
    def streamlines(self) -> list:
        return list(self.reference.streamlines) + list(self.cuts)

    def to_json(self) -> dict:
        """The `mesh` output of DESIGN.md."""
        return {
            "nodes": self.mesh.nodes.tolist(),
            "quads": self.mesh.quads.tolist(),
            "block_of_quad": self.mesh.block_of_quad.tolist(),
            "singularities": [{"xy": s.xy.tolist(), "valence": s.valence}
                              for s in self.reference.field.singularities],
            "streamlines": [line.points.tolist() for line in self.streamlines],
            "method": self.method,
            "fallback": list(self.fallback),
            "structured": self.structured,
            "structured_share": self.structured_share,
            "healed": list(self.domain.healed),
            **({"problem": self.problem} if self.problem else {}),
            "quality": dict(self.quality),
            "timings": dict(self.timings),
        }


def mesh_domain(domain: Domain, size: float | None = None, nodes: int = 2048,
                method: str = "numerical", smoothing: bool = True,
                learned_streamlines=None, seconds: float | None = None) -> MeshResult:
    """Domain to quad mesh.

    method "numerical" traces the streamlines; "cnn" takes them from
    ``learned_streamlines(domain, background, field) -> (lines, problems)`` (see
    infer.cnn; core itself never imports onnxruntime), and if those do not cut the domain
    into four-sided blocks, every streamline is traced numerically instead, so every valid
    input still gets a valid mesh.  "auto" is "cnn" when a learned source is given.
    ``seconds``: the time the caller allows (the command line's --time-limit); the
    second layout on a finer background is tried only when it should fit in it.
    """
    if method not in ("numerical", "auto", "cnn"):
        raise ValueError(f"unknown method {method!r} (auto, cnn or numerical)")
    if method == "auto":
        method = "cnn" if learned_streamlines is not None else "numerical"
    if method == "cnn" and learned_streamlines is None:
        raise ValueError("the cnn method needs a model")
    size = default_size(domain) if size is None else float(size)
    if not size > 0:
        raise ValueError(f"element size must be positive, got {size}")
    # Every copy of the part is meshed in one frame (core.layout_frame) and turned back.
    frame = frame_of(domain)
    framed = framed_domain(domain, frame)
    if learned_streamlines is not None:
        learned_streamlines = _learned_in_frame(learned_streamlines, frame)
    # Small round holes are squares to the layout only (input.small_holes): the result
    # holds the part as given, whose curves the exports name.
    unit_size = framed_size(size, frame)
    layout = same_frame(squared_holes(framed, unit_size), framed, domain, frame)
    result = _best_layout(layout, unit_size, nodes, method, smoothing, learned_streamlines,
                          seconds)
    if method == "numerical" and result.structured_share < 1.0:
        result = _with_more_holes_squared(result, framed, domain, frame, unit_size, nodes,
                                          smoothing, seconds)
    return world_result(result, frame, domain, size)


def _with_more_holes_squared(result, framed, domain, frame, size, nodes, smoothing, seconds):
    """Where the layout leaves free faces and the part has round holes a little over
    SMALL_HOLE sizes across (under SQUARED_RESCUE), the layout with those squared too,
    if its mesh is better (input.small_holes).  Not for every such hole: most of them
    read round give rings of quads that follow the rim, better than a square's corners
    (3 more irregular vertices on as1_plate's bolt holes, a worst element 0.01 lower)."""
    layout = squared_holes(framed, size, SQUARED_RESCUE)
    if sum(map(is_quartered, layout.loops)) == sum(map(is_quartered, result.domain.loops)):
        return result  # no hole of that size: the same layout again
    spent = result.timings["total"]
    if seconds is not None and (1.0 + FINER_COST) * spent > seconds:
        return result
    layout = same_frame(layout, framed, domain, frame)
    # Only a first layout that is all blocks is worth finishing: where squares leave free
    # faces too, the rescue is given up (held-out 0037 at diameter/100, 9 s in all, lost
    # 14 s finishing a worse one on the finer background).
    try:
        other = _mesh_on_background(layout, size, nodes, "numerical", smoothing, None,
                                    stop_at_free=True)
    except LeavesFreeFaces as exc:
        result.timings["other_holes"] = exc.seconds
        result.timings["total"] += exc.seconds
        return result
    best, worse = (other, result) if _better(other, result) else (result, other)
    best.timings["other_holes"] = worse.timings["total"]
    best.timings["total"] += worse.timings["total"]
    return best


def _learned_in_frame(learned_streamlines, frame):
    """A learned source reads the part in its own frame (its network was trained on
    parts as drawn): it is handed the layout's domain, background and field turned back,
    and its lines are put in the frame."""
    def in_frame(domain, background, field):
        lines, problems = learned_streamlines(world_domain(domain, frame),
                                              world_background(background, frame),
                                              world_field(field, frame))
        return [framed_line(line, frame) for line in lines], problems

    return in_frame


def _best_layout(domain, size, nodes, method, smoothing, learned_streamlines, seconds):
    """mesh_domain's layout, on a finer background too where the first leaves free faces."""
    if method != "numerical" or FINER_BACKGROUND <= 1:
        return _mesh_on_background(domain, size, nodes, method, smoothing, learned_streamlines)
    # Free faces left: the field may not resolve the part's small features (a gear's
    # roots, bolt holes of a few elements, notches) on `nodes` background nodes.  The
    # layout on a finer background is tried too, and the better mesh kept: more of it in
    # blocks, then the better worst element.  Both runs are decided by the geometry
    # alone, so every copy of the part picks the same one.  A first layout that leaves
    # free faces is not finished (its freeing rounds and unstructured fills cost more
    # than the finer try) unless the finer one leaves more than 1 - GOOD_ENOUGH of its
    # quads out of blocks (nist_ctc04_plate at its default size: 3 s more for 0.905
    # against the finer layout's 0.975).
    traced = None
    try:
        result = _mesh_on_background(domain, size, nodes, method, smoothing,
                                     learned_streamlines, stop_at_free=True)
        spent = result.timings["total"]
    except LeavesFreeFaces as exc:
        result, spent, traced = None, exc.seconds, exc.traced
    if result is not None and result.structured_share >= 1.0:
        return result
    if seconds is not None and (1.0 + FINER_COST) * spent > seconds:
        # No time for it: a mesh now beats a better one past the limit.
        return result or _mesh_on_background(domain, size, nodes, method, smoothing,
                                             learned_streamlines, traced=traced)
    finer = _mesh_on_background(domain, size, nodes * FINER_BACKGROUND, method, smoothing,
                                learned_streamlines)
    fair, share = _mesh_key(finer.mesh)[:2]
    if result is None and fair and share >= GOOD_ENOUGH:  # hardly anything left to beat
        finer.timings["other_background"] = spent
        finer.timings["total"] += spent
        return finer
    if result is None:  # the first layout finished from its streamlines
        result = _mesh_on_background(domain, size, nodes, method, smoothing,
                                     learned_streamlines, traced=traced)
        traced_seconds = sum(traced[3].values())
        result.timings["total"] += spent - traced_seconds
    best, other = (finer, result) if _better(finer, result) else (result, finer)
    best.timings["other_background"] = other.timings["total"]
    best.timings["total"] += other.timings["total"]
    return best


FINER_BACKGROUND = 4  # times the background nodes of the second try where free faces are left
FINER_COST = 2.0  # the second try's time, at most about this many times the first's
FAIR_JACOBIAN = 0.2  # a worst element below this outweighs a higher structured share
GOOD_ENOUGH = 0.97  # a finer layout this much in blocks (and fair) is not raced by the first


def _better(first: MeshResult, second: MeshResult) -> bool:
    """More of it in blocks, then the better worst element; but a mesh whose worst
    element is below FAIR_JACOBIAN loses to one that has none (a near-flat quad costs an
    analysis more than a few unstructured quads do)."""
    return _mesh_key(first.mesh) > _mesh_key(second.mesh)


def _mesh_key(mesh) -> tuple:
    worst = round(float(scaled_jacobians(mesh.nodes, mesh.quads).min()), 9)
    return (worst >= FAIR_JACOBIAN, round(structured_share(mesh), 9), worst)


class LeavesFreeFaces(Exception):
    """The first layout leaves free faces (``stop_at_free``): not worth finishing yet."""

    def __init__(self, seconds: float, traced=None):
        super().__init__("the layout leaves free faces")
        self.seconds = seconds
        self.traced = traced  # (background, field, lines, timings): what finishing reuses


def _mesh_on_background(domain, size, nodes, method, smoothing, learned_streamlines,
                        stop_at_free=False, traced=None):
    """mesh_domain on a background of ``nodes`` nodes; LeavesFreeFaces, with the seconds
    spent and what was traced, if ``stop_at_free`` and the first partition has faces that
    are no blocks.  ``traced``: such an exception's, to finish that layout without
    building its background, field and streamlines again."""
    if traced is None:
        timings = {}
        # The cnn path needs the node count its network was trained for; tracing does not.
        background, field = background_and_field(domain, nodes, timings,
                                                 strict=method == "cnn", feature_size=size)
        # Pairs of singular points that cancel are no structure (field.pairs): the layout
        # (and the result's singular points) is made from the others.
        field = without_cancelling_pairs(field, background.element_size)
        clock = time.perf_counter()
        if method == "cnn":
            lines, _ = learned_streamlines(domain, background, field)
        else:
            lines = trace_streamlines(domain, background, field)
        lines = _t_mesh(domain, background, field, lines, size)
        timings["reconstruction" if method == "cnn" else "tracing"] = \
            time.perf_counter() - clock
    else:
        background, field, lines, timings = traced
        timings = dict(timings)
    problem = ""
    try:
        try:
            try:
                cuts, partition, counts, mesh = blocks_and_mesh(
                    domain, background, field, lines, size, smoothing, timings,
                    allow_free=method != "cnn", stop_at_free=stop_at_free)
            except LeavesFreeFaces as exc:
                exc.traced = (background, field, lines,
                              {k: timings[k] for k in ("background", "field", "tracing")
                               if k in timings})
                # The rounds' clock saw only its own stages.
                exc.seconds += sum(exc.traced[3].values())
                raise
        except PartitionError:
            if method != "cnn":
                raise
            # The learned streamlines gave no valid block mesh: trace them all instead.
            clock = time.perf_counter()
            lines = tuple(dataclasses.replace(line, fallback=True)
                          for line in trace_streamlines(domain, background, field))
            lines = _t_mesh(domain, background, field, lines, size)
            timings["fallback_tracing"] = time.perf_counter() - clock
            cuts, partition, counts, mesh = blocks_and_mesh(domain, background, field, lines,
                                                             size, smoothing, timings)
    except PartitionError as exc:
        # The rounds dissolved every line: tried again with free faces filled finer;
        # failing that, never leave a valid input without a mesh, nor with one worse
        # than gmsh's own.
        finer = _with_finer_fills(domain, background, field, lines, size, smoothing,
                                  timings) if method != "cnn" else None
        if finer is not None:
            cuts, partition, counts, mesh = finer
        else:
            cuts, partition, counts, mesh, problem = _stand_in(
                domain, background, field, size, smoothing, timings, exc)
    problem = problem or free_face_problem(partition)
    clock = time.perf_counter()
    quality = mesh_quality(domain, mesh)
    timings["quality"] = time.perf_counter() - clock
    timings["total"] = sum(timings.values())
    reference = Reference(domain, background, field, tuple(lines), None, dict(timings))
    fallback = [k for k, line in enumerate(lines) if line.fallback] if method == "cnn" else []
    return MeshResult(domain=domain, reference=reference, cuts=cuts, partition=partition,
                      counts=counts, mesh=mesh, quality=quality, size=size, method=method,
                      fallback=fallback, timings=timings, structured=not problem,
                      problem=problem)


def _with_finer_fills(domain, background, field, lines, size, smoothing, timings):
    """blocks_and_mesh again, its free faces that cannot be filled tried with their
    boundary segments split (quadmesh._finer_free_face) before their lines are
    dissolved; None if that leaves no block partition either.  Only where the rounds
    dissolved every line (NIST CTC 02's logo plate: its logo's strokes, a fraction of an
    element wide, crossed the chords of its sides; the whole face then went to gmsh, 0 %
    in blocks, worst 0.11, 142 irregular vertices; with the logo's face filled finer,
    one free face, worst 0.62, 59), so that nothing meshed in blocks changes."""
    clock = time.perf_counter()
    try:
        return blocks_and_mesh(domain, background, field, lines, size, smoothing, {},
                               finer_fills=True)
    except PartitionError:
        return None
    finally:
        timings["finer_fills"] = time.perf_counter() - clock


def _stand_in(domain, background, field, size, smoothing, timings, exc):
    """(cuts, partition, counts, mesh, problem) where no block partition came out:
    gmsh's quasi-structured quads, never a mesh worse than gmsh's own."""
    problem = f"no block structure ({exc}); gmsh's quasi-structured quads stand in"
    cuts, partition, counts = [], Partition(np.zeros((0, 2)), [], [], []), np.zeros(0, int)
    clock = time.perf_counter()
    mesh = gmsh_quad_mesh(domain, size)
    timings["quad_mesh"] = time.perf_counter() - clock
    if not is_valid_mesh(mesh) and isinstance(exc, PoorMesh):
        # gmsh's own quads fold here: our poor but unfolded mesh is the better one.
        cuts, partition, counts, mesh = exc.result
        problem = f"{free_face_problem(partition) or 'blocks'}, worst scaled Jacobian " \
                  f"{exc.worst:.3f}: gmsh's own quads fold here"
    elif not is_valid_mesh(mesh):
        # gmsh's own quads fold here: the domain as one free face stands in instead.
        clock = time.perf_counter()
        try:
            cuts, partition, counts, mesh = blocks_and_mesh(
                domain, background, field, (), size, smoothing, {}, worst_allowed=0.0)
            problem = f"no block structure ({exc}); unstructured quads stand in"
        except PartitionError:
            pass  # nothing better to be had: gmsh's mesh as it is
        timings["quad_mesh"] += time.perf_counter() - clock
    return cuts, partition, counts, mesh, problem


def _t_mesh(domain, background, field, lines, size) -> tuple:
    """One line for each short lens (layout.lenses), traces cut where they first meet an
    earlier one (see layout.motorcycle), none in a sliver wedge at a corner
    (layout.wedges), and a kite at each cusp's tip (layout.cusps)."""
    lines = without_short_lenses(lines, background.element_size)
    lines = stop_at_first_hits(lines, background.element_size, 1e-9 * domain.size)
    lines = without_corner_wedges(domain, background, lines, size)
    return with_cusp_kites(domain, background, field, lines, size)


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
        return found if found is not None and _mesh_key(found[3]) > _mesh_key(plain[3]) \
            else plain
    finally:
        timings.update(spent)


GOOD_JACOBIAN = 0.5  # a mesh all in blocks and no worse than this is not raced


def _whole_and_good(mesh) -> bool:
    _, share, worst = _mesh_key(mesh)
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
            before, after = _mesh_key(found[3]), _mesh_key(cut[3])
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
    return merged if _mesh_key(merged[3]) > _mesh_key(found[3]) else found


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


def crossing_quads(nodes, quads) -> np.ndarray:
    """Quads with an edge that crosses another quad's edge: where blocks fold over each
    other though every element is positive."""
    directed = np.concatenate([quads[:, [k, (k + 1) % 4]] for k in range(4)])
    owner = np.tile(np.arange(len(quads)), 4)
    key = np.sort(directed, axis=1)
    edges = np.unique(key, axis=0)
    a, b = nodes[edges[:, 0]], nodes[edges[:, 1]]
    reach = float(np.hypot(*(b - a).T).max())
    from scipy.spatial import cKDTree

    pairs = cKDTree(0.5 * (a + b)).query_pairs(reach, output_type="ndarray")
    i, j = pairs[:, 0], pairs[:, 1]
    shared = (edges[i][:, :, None] == edges[j][:, None, :]).any(axis=(1, 2))
    i, j = i[~shared], j[~shared]

    def orient(o, u, v):
        return (u[:, 0] - o[:, 0]) * (v[:, 1] - o[:, 1]) - (u[:, 1] - o[:, 1]) * (v[:, 0] - o[:, 0])

    cross = (orient(a[i], b[i], a[j]) * orient(a[i], b[i], b[j]) < 0) \
        & (orient(a[j], b[j], a[i]) * orient(a[j], b[j], b[i]) < 0)
    hit = np.zeros(len(edges), dtype=bool)
    hit[i[cross]] = hit[j[cross]] = True
    bad = np.zeros(len(quads), dtype=bool)
    _, inverse = np.unique(key, axis=0, return_inverse=True)
    bad[owner[hit[inverse.ravel()]]] = True
    return bad


def is_valid_mesh(mesh) -> bool:
    """No inverted or degenerate quad, no overlap, no gap, no hole filled over."""
    return bool(len(mesh.quads)) and scaled_jacobians(mesh.nodes, mesh.quads).min() > 0 \
        and tiles_exactly(mesh.nodes, mesh.quads) \
        and free_edges_on_boundary(mesh.quads, mesh.boundary) \
        and boundary_on_free_edges(mesh.quads, mesh.boundary)


def free_edges_on_boundary(quads, boundary) -> bool:
    """Every edge used by one quad only joins two boundary nodes: no gap inside.

    (A gap's own edges enclose a negative area, so tiles_exactly cannot see it.)"""
    directed = np.concatenate([quads[:, [k, (k + 1) % 4]] for k in range(4)])
    key = np.sort(directed, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    free = key[counts[inverse.ravel()] == 1]
    return bool(boundary[free].all())


def boundary_on_free_edges(quads, boundary) -> bool:
    """Every used boundary node is an end of an edge used by one quad only: no boundary
    loop lies inside the mesh (a hole filled over)."""
    directed = np.concatenate([quads[:, [k, (k + 1) % 4]] for k in range(4)])
    key = np.sort(directed, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    on_free = np.zeros(len(boundary), dtype=bool)
    on_free[key[counts[inverse.ravel()] == 1].ravel()] = True
    used = np.zeros(len(boundary), dtype=bool)
    used[quads.ravel()] = True
    return bool(np.all(on_free[boundary & used]))
