"""Domain to block-structured quad mesh in one call; the command line and FreeCAD use this.

The result carries every stage (background mesh, field, streamlines, partition, segment
counts, quad mesh, quality) and the time each took, so callers can draw or export any of
them without recomputing.
"""

from __future__ import annotations

import dataclasses
import functools
import time
from dataclasses import dataclass, field

import numpy as np

from .field.pairs import without_cancelling_pairs
from .field.reference import Reference, background_and_field
from .input.domain import Domain
from .input.features import boundary_features
from .input.pose import default_size
from .input.small_holes import SQUARED_RESCUE, is_quartered, squared_holes
from .layout.cusps import with_cusp_kites
from .layout.lenses import without_short_lenses
from .layout.motorcycle import stop_at_first_hits
from .layout.partition_types import Partition, PartitionError
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
from .mesh.quadmesh import QuadMesh
from .mesh.quality import mesh_quality, structured_share
from .mesh.validity import is_valid_mesh
from .rounds import (
    LeavesFreeFaces,
    PoorMesh,
    blocks_and_mesh,
    fair_but_at_tips,
    free_face_problem,
    mesh_key,
)


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
    default = default_size(domain)
    size = default if size is None else float(size)
    if not size > 0:
        raise ValueError(f"element size must be positive, got {size}")
    finer_than_default = default / size
    # Every copy of the part is meshed in one frame (core.layout_frame) and turned back.
    frame = frame_of(domain)
    framed = framed_domain(domain, frame)
    if learned_streamlines is not None:
        learned_streamlines = _learned_in_frame(learned_streamlines, frame)
    # Small round holes are squares to the layout only (input.small_holes): the result
    # holds the part as given, whose curves the exports name.
    unit_size = framed_size(size, frame)
    layout = same_frame(squared_holes(framed, unit_size), framed, domain, frame)
    rescue = _SquaredRescue(framed, layout, domain, frame, unit_size, nodes, smoothing)
    result = _best_layout(layout, unit_size, nodes, finer_than_default, method, smoothing,
                          learned_streamlines, seconds, rescue)
    if method == "numerical" and result.structured_share < 1.0:
        result = _with_more_holes_squared(result, rescue, seconds)
    return world_result(result, frame, domain, size)


class _SquaredRescue:
    """The layout with the round holes a little over SMALL_HOLE sizes across (under
    SQUARED_RESCUE) squared too (input.small_holes), tried at most once: by the race
    before its third background (a plate of bench.plates seed 11 spent 3 s on a third
    layout that lost to this one's 0.45 s) or after it (_with_more_holes_squared).
    Only a first partition that is all blocks is finished: where squares leave free faces
    too, the rescue is given up (held-out 0037 at diameter/100, 9 s in all, lost 14 s
    finishing a worse one on the finer background)."""

    def __init__(self, framed, layout, domain, frame, size, nodes, smoothing):
        self._frames = (framed, layout, domain, frame)
        self.size, self.nodes, self.smoothing = size, nodes, smoothing
        self.outcome = None

    @functools.cached_property
    def layout(self):
        """The squared layout, None where no hole is of that size (built only when asked:
        most parts never need it)."""
        framed, layout, domain, frame = self._frames
        squared = squared_holes(framed, self.size, SQUARED_RESCUE)
        same = sum(map(is_quartered, squared.loops)) == sum(map(is_quartered, layout.loops))
        return None if same else same_frame(squared, framed, domain, frame)

    def available(self) -> bool:
        return self.layout is not None

    def __call__(self) -> tuple:
        """(its mesh, or None where its first partition has free faces; the seconds),
        the same on every call."""
        if self.outcome is None:
            try:
                other = _mesh_on_background(self.layout, self.size, self.nodes, "numerical",
                                            self.smoothing, None, stop_at_free=True)
                self.outcome = (other, other.timings["total"])
            except LeavesFreeFaces as exc:
                self.outcome = (None, exc.seconds)
        return self.outcome


def _with_more_holes_squared(result, rescue, seconds):
    """Where the layout leaves free faces and the part has round holes a little over
    SMALL_HOLE sizes across, the layout with those squared too (_SquaredRescue), if its
    mesh is better.  Not for every such hole: most of them read round give rings of
    quads that follow the rim, better than a square's corners (3 more irregular vertices
    on as1_plate's bolt holes, a worst element 0.01 lower)."""
    if not rescue.available():
        return result  # no hole of that size: the same layout again
    tried = rescue.outcome is not None  # by the race, which counted a failed try's time
    spent = result.timings["total"]
    if not tried and seconds is not None and (1.0 + FINER_COST) * spent > seconds:
        return result
    other, cost = rescue()
    if other is None:
        if not tried:
            _charge(result, cost, "other_holes")
        return result
    best, worse = (other, result) if _better(other, result) else (result, other)
    _charge(best, worse.timings["total"], "other_holes")
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


def finest_background_nodes(nodes: int, finer_than_default: float) -> int:
    """Background nodes of the third try: four times the second try's, or, for elements
    finer than the default size (diameter / 40), as many per quad as the second try has
    at the default size, whichever is more (32768 and 51200 at diameter / 100 for
    ``nodes`` 2048).

    ``nodes`` is sized for the default elements; at diameter / 100 (6.25 times the
    quads) even the second try's 4 x 2048 nodes are coarser than the mesh around small
    features: holes a few elements from an edge or from each other got their valence-5
    points on the rim, lines along it, and free faces.  Random plates at diameter / 100
    (bench.plates --seed 7 --d100: four of 40 short of blocks) and the corpus's two logo
    plates and perforated plate are all blocks at 51200 nodes (25600: one of them
    still short).  At the default size, held-out Prusa MINI y-plate-front f8 is all
    blocks on 32768 nodes (0.965 on 8192, 41 s in all)."""
    return int(round(nodes * FINER_BACKGROUND * max(FINER_BACKGROUND,
                                                    finer_than_default ** 2)))


def _best_layout(domain, size, nodes, finer_than_default, method, smoothing,
                 learned_streamlines, seconds, rescue=None):
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
    # against the finer layout's 0.975).  Where the finer one is not all blocks and fair,
    # a third layout on a background finer still may end the race (_third_layout).
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
    fair, share = _fair_and_share(finer, size)
    second_whole = fair and share >= 1.0
    if not second_whole and rescue is not None and rescue.available():
        # The holes squared first: cheaper than the third layout where it does it.
        squared, cost = rescue()
        if squared is not None and _whole_and_fair(squared, size):
            # The round holes' layouts lost (their time is "other_holes", as after the race).
            _charge(squared, spent + finer.timings["total"], "other_holes")
            return squared
        if squared is None:
            _charge(finer, cost)  # else it is raced at the end (_with_more_holes_squared)
    if not second_whole:
        # Before the first is finished (17 s of freeing rounds on a plate at diameter/100
        # whose third layout took 4 s).
        finest, whole = _third_layout(domain, size, nodes, finer_than_default, method,
                                      smoothing, learned_streamlines, seconds, finer,
                                      spent + finer.timings["total"])
        if whole:
            _charge(finest, spent + finer.timings["total"])
            return finest
        if finest is not None and _better(finest, finer) \
                and finest.structured_share >= finer.structured_share:
            # Not all blocks, but better than the second and as much in blocks: it takes
            # the second's place (held-out Prusa i3 y-belt-idler f73 at its default
            # size: 0.989 in blocks, 24 irregular vertices, against 0.985 and 27, both
            # fair; blend_sawtooth there: 0.481 and fair against 0.473).  Less in blocks,
            # though fair where the second is not, it does not: it was tried for blocks
            # (blend_sawtooth at diameter/100: 0.62 and 50 irregular vertices against
            # 0.948 and 20).  Whether the first is finished is still the second's to
            # say: a third fair and 0.973 in blocks would leave blend_horn_plate's
            # first, all blocks, unfinished.
            _charge(finest, finer.timings["total"])
            finer = finest
        elif finest is not None:
            _charge(finer, finest.timings["total"])
    if result is None and fair and share >= GOOD_ENOUGH:  # hardly anything left to beat
        _charge(finer, spent)
        return finer
    if result is None:  # the first layout finished from its streamlines
        result = _mesh_on_background(domain, size, nodes, method, smoothing,
                                     learned_streamlines, traced=traced)
        traced_seconds = sum(traced[3].values())
        result.timings["total"] += spent - traced_seconds
    best, other = (finer, result) if _better(finer, result) else (result, finer)
    _charge(best, other.timings["total"])
    return best


def _third_layout(domain, size, nodes, finer_than_default, method, smoothing,
                  learned_streamlines, seconds, second, spent):
    """Where the second layout is not all blocks and fair: (the layout on a background
    finer still, finest_background_nodes, or None where it would not fit in ``seconds``
    after the ``spent`` ones; whether it ends the race: all blocks and fair).  Not
    whole, it does not: the first, finished, may be all blocks yet (blend_horn_plate at
    its default size: 1.0 against the third's 0.973).  Where the second has more than
    1 - GOOD_ENOUGH of its quads out of blocks, all blocks is enough: the rule that a
    quad under FAIR_JACOBIAN loses to a few unstructured quads is not for a quarter of
    them (held-out Prusa MINI y-plate-front f8: 75 % in blocks, worst 0.243, against all
    blocks, worst 0.183, gmsh alg. 11 0.075)."""
    finest_nodes = finest_background_nodes(nodes, finer_than_default)
    # Its time, at most about FINER_COST times the second's, whose background, field and
    # traces grow with the background nodes (the rest with the quads, the same).
    grows = sum(second.timings.get(k, 0.0) for k in ("background", "field", "tracing"))
    guess = FINER_COST * (second.timings["total"] - grows
                          + grows * finest_nodes / (nodes * FINER_BACKGROUND))
    if seconds is not None and spent + guess > seconds:
        return None, False
    finest = _mesh_on_background(domain, size, finest_nodes, method, smoothing,
                                 learned_streamlines)
    whole = _whole_and_fair(finest, size) or (
        finest.structured_share >= 1.0 and second.structured_share < GOOD_ENOUGH
        and finest.quality["min_scaled_jacobian"] > 0)
    return finest, whole


def _fair_and_share(result: MeshResult, size: float) -> tuple:
    """(no quad under FAIR_JACOBIAN, or none but at a cusp's tip where all is blocks;
    the structured share)."""
    fair, share = mesh_key(result.mesh)[:2]
    fair = fair or (share >= 1.0 and fair_but_at_tips(result.mesh, result.reference.mesh, size))
    return fair, share


def _whole_and_fair(result: MeshResult, size: float) -> bool:
    """All in blocks with no quad under FAIR_JACOBIAN but at a cusp's tip."""
    fair, share = _fair_and_share(result, size)
    return fair and share >= 1.0


def _charge(result: MeshResult, seconds: float, key: str = "other_background") -> None:
    """Count the seconds of a layout not kept in the kept one's total and under ``key``
    ("other_holes": the layouts with the round holes read otherwise)."""
    result.timings[key] = result.timings.get(key, 0.0) + seconds
    result.timings["total"] += seconds


FINER_BACKGROUND = 4  # times the background nodes of the second try where free faces are left
FINER_COST = 2.0  # the second try's time, at most about this many times the first's
GOOD_ENOUGH = 0.97  # a finer layout this much in blocks (and fair) is not raced by the first


def _better(first: MeshResult, second: MeshResult) -> bool:
    """More of it in blocks, then the better worst element; but a mesh whose worst
    element is below rounds.FAIR_JACOBIAN loses to one that has none (a near-flat quad costs an
    analysis more than a few unstructured quads do)."""
    return mesh_key(first.mesh) > mesh_key(second.mesh)



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
