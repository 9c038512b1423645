"""Command line: `python -m quadcnn_wb COMMAND ...` (also installed as `quadcnn`).

Exit status per DESIGN.md: 0 done; 2 bad input or unusable request, with one line on
stderr starting with `error:` and no traceback; 1 only for a bug.
"""

from __future__ import annotations

import argparse
import signal
import sys
from pathlib import Path

from .core.atomic import write_json_atomic
from .core.field.background import BackgroundMeshError, background_mesh
from .core.field.framefield import FieldError
from .core.input.domain import DomainError
from .core.input.load import load_domain
from .core.layout.partition_types import PartitionError
from .infer.predictor import ModelError


class UsageError(Exception):
    """A request the program cannot honour (bad option values, unwritable output)."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one `error:` line, exit 2, as for every other bad request
        self.exit(2, f"error: {message} (see '{self.prog} --help')\n")


def _whole_number(minimum: int):
    """argparse type: an integer of at least ``minimum``."""
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"expected at least {minimum}, got {value}")
        return value

    return parse


_positive_int = _whole_number(8)  # node counts
DEFAULT_TIME_LIMIT = 120.0  # seconds, for background, field and mesh
_positive_count = _whole_number(1)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="quadcnn", description="Block-structured quad meshing guided by "
                     "frame fields and a CNN (see README.md).")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    bg = _stage_parser(commands, "background", "triangular background mesh of a domain",
                       "target node count (default 2048, held within 5%%)",
                       "write the mesh as JSON (DESIGN.md 'background')",
                       "write a picture of the mesh, boundary and corners")
    bg.set_defaults(run=_run_background)

    fd = _stage_parser(commands, "field", "cross field, singular points, streamlines, labels",
                       "background mesh node count (default 2048)",
                       "write frames, singularities, streamlines and labels as JSON "
                       "(DESIGN.md 'field')",
                       "write a picture: crosses, singular points, streamlines, label-1 "
                       "vectors")
    fd.set_defaults(run=_run_field)

    ms = _stage_parser(commands, "mesh", "block-structured quad mesh",
                       "background mesh node count (default 2048)",
                       "mesh file: .json (DESIGN.md 'mesh'), .msh, .vtk or .inp "
                       "(CalculiX/Abaqus, CPS4)",
                       "write a picture: blocks coloured, streamlines, singular points")
    ms.add_argument("--method", choices=["auto", "cnn", "numerical"], default="auto",
                    help="how streamlines are found (default auto: a matching model if one "
                    "is installed, else numerical tracing)")
    ms.add_argument("--model", help="ONNX model for the cnn method")
    ms.add_argument("--size", type=_positive_float, help="target element size (default: the "
                    "part's diameter / 40)")
    ms.set_defaults(run=_run_mesh)

    fam = commands.add_parser("families", help="list the shape families and their parameters")
    fam.set_defaults(run=_run_families)

    ds = commands.add_parser("dataset", help="generate training data for one shape family")
    ds.add_argument("family")
    ds.add_argument("-n", type=_positive_count, default=2000, help="samples (default 2000)")
    ds.add_argument("--seed", type=int, default=0)
    ds.add_argument("--nodes", type=_positive_int, default=2048)
    ds.add_argument("--workers", type=_positive_count, help="processes (default: all cores)")
    ds.add_argument("-o", "--output", required=True, help="data set file (.npz)")
    ds.set_defaults(run=_run_dataset)

    tr = commands.add_parser("train", help="train a network on a data set, export ONNX")
    tr.add_argument("data", help="data set from 'quadcnn dataset'")
    tr.add_argument("-o", "--output", required=True, help="model file (.onnx); metadata "
                    "goes beside it (.json)")
    tr.add_argument("--epochs", type=_positive_count, default=30)
    tr.add_argument("--seed", type=int, default=0)
    tr.add_argument("--recipe", choices=["paper", "fast", "rays"], default="paper")
    tr.add_argument("--threads", type=_positive_count, default=2)
    tr.add_argument("--patience", type=_positive_count, default=6)
    tr.add_argument("--minutes", type=_positive_float,
                    help="stop after this wall time, keeping the best epoch so far")
    tr.add_argument("--init", help="start from the best weights of a checkpoint (.ckpt.pt "
                    "written beside a model by an earlier run of the same recipe)")
    tr.set_defaults(run=_run_train)

    ev = commands.add_parser("evaluate", help="label metrics of a model on a data set")
    ev.add_argument("model", help="model file (.onnx)")
    ev.add_argument("data", help="data set from 'quadcnn dataset'")
    ev.add_argument("-o", "--output", help="write the metrics as JSON")
    ev.add_argument("--threads", type=_positive_count, default=2)
    ev.set_defaults(run=_run_evaluate)
    return parser


def _stage_parser(commands, name, summary, nodes_help, output_help, png_help):
    """A sub-command that reads a domain and writes a file and a picture of one stage."""
    sub = commands.add_parser(name, help=summary)
    sub.add_argument("input", help="Domain JSON v1, STEP, BREP or IGES file")
    sub.add_argument("--nodes", type=_positive_int, default=2048, help=nodes_help)
    sub.add_argument("-o", "--output", help=output_help)
    sub.add_argument("--png", help=png_help)
    sub.add_argument("--time-limit", type=_positive_float, default=DEFAULT_TIME_LIMIT,
                     help=f"give up (exit 2) after this many seconds (default "
                     f"{DEFAULT_TIME_LIMIT:g}; a 2048-node run takes well under one)")
    return sub


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"expected a positive size, got {text!r}")
    return value


def _check_output(path, suffixes) -> Path | None:
    if path is None:
        return None
    path = Path(path)
    if path.suffix.lower() not in suffixes:
        raise UsageError(f"{path}: output must end in {' or '.join(sorted(suffixes))}")
    if not path.parent.is_dir() and str(path.parent):
        raise UsageError(f"{path}: the folder {path.parent} does not exist")
    return path


def _run_background(args) -> None:
    out = _check_output(args.output, {".json"})
    png = _check_output(args.png, {".png"})
    domain = load_domain(args.input)
    mesh = background_mesh(domain, nodes=args.nodes)
    if out:
        write_json_atomic(out, {**mesh.to_json(), "healed": list(domain.healed)})
    if png:
        from .viz.background_plot import plot_background

        plot_background(domain, mesh, png)
    _report_healing(domain)
    print(f"{mesh.n_nodes} nodes, {len(mesh.triangles)} triangles, "
          f"{len(mesh.boundary_nodes)} on the boundary, {len(mesh.corner_nodes)} corners")


def _run_field(args) -> None:
    from .core.field.reference import numerical_reference

    out = _check_output(args.output, {".json"})
    png = _check_output(args.png, {".png"})
    ref = numerical_reference(load_domain(args.input), nodes=args.nodes)
    if out:
        write_json_atomic(out, ref.to_json())
    if png:
        from .viz.field_plot import plot_field

        plot_field(ref.domain, ref.mesh, ref.field, ref.streamlines, png, labels=ref.labels)
    counts = ref.field.valences()
    _report_healing(ref.domain)
    capped = sum(line.capped for line in ref.streamlines)
    print(f"{ref.mesh.n_nodes} nodes, {counts[3]} valence-3 and {counts[5]} valence-5 singular "
          f"points, {len(ref.field.corner_sources)} concave corners, {len(ref.streamlines)} "
          f"streamlines ({capped} capped), {int(ref.labels.sum())} label-1 vectors")


def _streamline_source(args, domain):
    """(learned streamline source or None, method name) for --method and --model."""
    from .infer.cnn import cnn_streamlines
    from .infer.models import model_for_method

    if args.model:
        return cnn_streamlines(args.model), "cnn"
    entry = model_for_method(domain, args.method, "train one ('quadcnn dataset' + 'quadcnn "
                             "train') or pass --model MODEL.onnx")
    if entry is None:
        return None, "numerical"
    return cnn_streamlines(entry.path), "cnn"


def _run_mesh(args) -> None:
    from .core.mesh.export import FORMATS, export
    from .core.pipeline import mesh_domain

    out = _check_output(args.output, FORMATS)
    png = _check_output(args.png, {".png"})
    domain = load_domain(args.input)
    source, method = _streamline_source(args, domain)
    limit = getattr(args, "time_limit", None)
    result = mesh_domain(domain, size=args.size, nodes=args.nodes, method=method,
                         learned_streamlines=source,
                         seconds=0.8 * limit if limit else None)
    if out:
        export(result, out)
    if png:
        from .viz.mesh_plot import plot_mesh

        plot_mesh(result, png)
    if not result.structured:
        print(f"warning: {result.problem}", file=sys.stderr)
    _report_healing(domain)
    q = result.quality
    print(f"{q['quads']} quads in {q['blocks']} blocks "
          f"({100 * result.structured_share:.0f} % of the quads in blocks), min scaled Jacobian "
          f"{q['min_scaled_jacobian']:.3f} (mean {q['mean_scaled_jacobian']:.3f}), "
          f"{q['irregular_vertices']} irregular vertices, "
          f"{len(result.reference.field.singularities)} singular points, "
          f"{result.timings['total']:.3f} s ({result.method})")


def _report_healing(domain) -> None:
    """One line per thing the input healing changed, so a user sees the part was touched."""
    for note in domain.healed:
        print(f"healed: {note}")


def _run_families(args) -> None:
    from .learn.families import FAMILIES

    for fam in FAMILIES.values():
        print(f"{fam.name}: {fam.description}; singular points: {fam.singularities[0]} "
              f"valence-3, {fam.singularities[1]} valence-5; topology {fam.topology}")
        for name, (lo, hi) in fam.ranges.items():
            print(f"    {name}: {lo:g} .. {hi:g}")


def _run_dataset(args) -> None:
    from .learn.dataset import generate, save_dataset
    from .learn.families import family

    try:
        topology = family(args.family).topology
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    out = _check_output(args.output, {".npz"})
    samples, dropped = generate(args.family, args.n, args.seed, nodes=args.nodes,
                                workers=args.workers)
    save_dataset(out, samples, {"family": args.family, "seed": args.seed, "requested": args.n,
                                "nodes": args.nodes, "dropped": dict(dropped),
                                "topology": topology})
    reasons = ", ".join(f"{k}: {v}" for k, v in sorted(dropped.items())) or "none"
    print(f"{len(samples)} samples written to {out}; dropped {sum(dropped.values())} "
          f"({reasons})")


def _run_train(args) -> None:
    try:
        from .learn.train import train
    except ImportError:
        raise UsageError("training needs PyTorch: .venv/bin/pip install -e '.[train]'") from None
    out = _check_output(args.output, {".onnx"})
    try:
        meta = train(args.data, out, epochs=args.epochs, seed=args.seed, recipe=args.recipe,
                     threads=args.threads, patience=args.patience, minutes=args.minutes,
                     init=args.init)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    m = meta["metrics_test_split"]
    print(f"{out}: test split IoU {m['iou']:.3f}, accuracy {m['accuracy']:.4f} "
          f"(all-zeros {m['zero_baseline_accuracy']:.4f}), best epoch "
          f"{meta['recipe']['best_epoch']}")


def _run_evaluate(args) -> None:
    from .infer.metrics import Confusion
    from .infer.predictor import ModelError, Predictor
    from .learn.dataset import load_dataset

    out = _check_output(args.output, {".json"})
    try:
        predictor = Predictor(args.model, threads=args.threads)
        samples, _ = load_dataset(args.data)
    except (ModelError, ValueError) as exc:
        raise UsageError(str(exc)) from None
    confusion = Confusion()
    for sample in samples:
        confusion.add(predictor.labels(sample.x), sample.y)
    metrics = confusion.metrics(len(samples))
    if out:
        write_json_atomic(out, metrics)
    print(" ".join(f"{k}={v:.4f}" if isinstance(v, float) else f"{k}={v}"
                   for k, v in metrics.items()))


class TimeLimitError(BaseException):
    """The run took longer than --time-limit.  An interrupt, like KeyboardInterrupt, not
    an Exception: it lands in whatever code runs when the alarm goes off, and a handler
    there for that code's own failures (gmsh's or onnxruntime's bare Exceptions, a data
    set's bad draw) must not swallow it (a loaded machine had it land in one: the run
    went on for 17 s and exited 0)."""


def _run_with_time_limit(args) -> None:
    """A hard ceiling on the whole run: no stage can keep the command line waiting.

    The alarm interrupts whatever Python code runs (gmsh and the solvers return to
    Python within milliseconds at these sizes); outputs are written atomically, so nothing
    half-written is left behind."""
    limit = getattr(args, "time_limit", None)
    if not limit or not hasattr(signal, "setitimer"):
        return args.run(args)

    message = f"gave up after {limit:g} s (--time-limit); try fewer --nodes or a larger --size"
    fired = []

    def give_up(signum, frame):
        fired.append(True)
        raise TimeLimitError(message)

    previous = signal.signal(signal.SIGALRM, give_up)
    signal.setitimer(signal.ITIMER_REAL, limit)
    try:
        return args.run(args)
    except BaseException as exc:
        # Landed inside an extension module's import, the alarm comes out as that
        # module's "ImportError: initialization failed" (onnxruntime's, on a cold start
        # past a 0.2 s limit): once the alarm has gone off, any failure is the time limit.
        if fired and not isinstance(exc, TimeLimitError):
            raise TimeLimitError(message) from exc
        raise
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        _run_with_time_limit(args)
    except (DomainError, BackgroundMeshError, FieldError, PartitionError, ModelError,
            UsageError, TimeLimitError, OSError) as exc:
        message = " ".join(str(exc).split())
        print(f"error: {message}", file=sys.stderr)
        return 2
    return 0
