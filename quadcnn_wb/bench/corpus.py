"""Real parts against gmsh's quasi-structured quad mesher:
`python -m quadcnn_wb.bench.corpus [--parts NAME ...] [--repeat N]`.

The bundled examples are the shapes the method was developed on; tests/corpus holds planar
faces cut from public CAD files exactly as the CAD kernel delivered them (circles stored
as several arcs, B-spline and ellipse edges, small gaps) and faces built the way a FreeCAD
user builds them (tests/corpus/SOURCES.md says where each one comes from).  Each part is
meshed at two sizes, the pipeline's default and its diameter / 100, by our numerical path
and by gmsh's Mesh.Algorithm = 11 on the same geometry (bench.mesh_vs_gmsh's runner); both
meshes are scored by our own quality code.  "share" is the share of our mesh that is
block-structured (0 where gmsh's quads stand in).  A part the importer refuses is printed
with the refusal; a mesher that fails or runs past --time-limit is printed with its error
and the loop goes on (the limit interrupts Python code; a call into gmsh finishes first).
"""

from __future__ import annotations

import argparse
import json
import signal
import statistics
from contextlib import contextmanager
from pathlib import Path

from ..core.input.domain import DomainError
from ..core.input.load import load_domain
from ..core.input.pose import diameter
from ..core.pipeline import default_size, mesh_domain
from .mesh_vs_gmsh import gmsh_quasi_structured, score

CORPUS = Path(__file__).resolve().parents[2] / "tests" / "corpus"
FINE_DIVISOR = 100  # the second size: the part's diameter / this
SAME_QUALITY = 1e-9  # worst scaled Jacobians this close are one (a quad at the same corner)


class MeshTimeLimit(RuntimeError):
    """One mesher ran past --time-limit."""


@contextmanager
def time_limit(seconds: float):
    """Raise MeshTimeLimit in the running Python code after `seconds` (0: no limit)."""
    if not seconds or not hasattr(signal, "setitimer"):
        yield
        return

    def give_up(signum, frame):
        raise MeshTimeLimit(f"ran past the {seconds:g} s time limit")

    previous = signal.signal(signal.SIGALRM, give_up)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def corpus_parts(corpus: Path):
    """(name, path, kind) for every part in the corpus manifest, in its order."""
    entries = json.loads((corpus / "manifest.json").read_text(encoding="utf-8"))
    return [(e["name"], corpus / e["file"], e["kind"]) for e in entries]


def ours(domain, size: float, repeat: int, limit: float) -> dict:
    """Our figures at `size` (median time over `repeat` runs)."""
    seconds = []
    for _ in range(repeat):
        with time_limit(limit):
            result = mesh_domain(domain, size=size)
        seconds.append(result.timings["total"])
    q = result.quality
    share = getattr(result, "structured_share", 1.0 if result.structured else 0.0)
    return {"share": float(share), "irregular": int(q["irregular_vertices"]),
            "min_sj": float(q["min_scaled_jacobian"]),
            "mean_sj": float(q["mean_scaled_jacobian"]), "quads": int(q["quads"]),
            "time": statistics.median(seconds), "problem": result.problem}


def peer(domain, size: float, repeat: int, limit: float) -> dict:
    """gmsh's figures at `size` (median meshing time over `repeat` runs)."""
    seconds = []
    for _ in range(repeat):
        with time_limit(limit):
            nodes, quads, boundary, elapsed = gmsh_quasi_structured(domain, size)
        seconds.append(elapsed)
    n_quads, min_sj, mean_sj, irregular = score(domain, nodes, quads, boundary)
    return {"irregular": irregular, "min_sj": min_sj, "mean_sj": mean_sj, "quads": n_quads,
            "time": statistics.median(seconds)}


def _attempt(run, *args) -> dict:
    try:
        return run(*args)
    except Exception as exc:  # a failure is a finding: print it and go on
        return {"error": f"{type(exc).__name__}: {' '.join(str(exc).split())}"}


OURS = (("share", 6, ".2f"), ("irr", 5, "d"), ("minSJ", 6, ".3f"), ("meanSJ", 6, ".3f"),
        ("quads", 7, "d"), ("time", 8, ".2f"))
PEER = OURS[1:]
KEYS = {"share": "share", "irr": "irregular", "minSJ": "min_sj", "meanSJ": "mean_sj",
        "quads": "quads", "time": "time"}


def _width(columns) -> int:
    return sum(w for _, w, _ in columns) + len(columns) - 1


def _cells(columns, r: dict) -> str:
    if "error" in r:
        return f"failed: {r['error']}"[:_width(columns)].ljust(_width(columns))
    return " ".join(f"{r[KEYS[label]]:>{w}{fmt}}" if label != "time" else
                    f"{r['time']:>{w - 1}{fmt}}s" for label, w, fmt in columns)


def _labels(columns) -> str:
    return " ".join(f"{label:>{w}}" for label, w, _ in columns)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--parts", nargs="+", metavar="NAME",
                        help="only these parts (names from tests/corpus/manifest.json)")
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--time-limit", type=float, default=300.0,
                        help="seconds allowed to one mesher on one part and size (0: none)")
    parser.add_argument("--corpus", type=Path, default=CORPUS, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.repeat < 1:
        parser.error("--repeat must be at least 1")
    parts = corpus_parts(args.corpus)
    if args.parts:
        known = {name for name, _, _ in parts}
        unknown = [name for name in args.parts if name not in known]
        if unknown:
            parser.error(f"not in the corpus: {', '.join(unknown)}")
        parts = [p for p in parts if p[0] in args.parts]

    print(f"{'':<21} {'':>9} | {'ours (numerical path)':<{_width(OURS)}} | "
          f"{'gmsh, Mesh.Algorithm 11':<{_width(PEER)}} | {'ours/gmsh':>9}")
    print(f"{'part':<21} {'size':>9} | {_labels(OURS)} | {_labels(PEER)} | {'time':>9}")
    refused, rows, fallbacks = [], [], []
    for name, path, _kind in parts:
        try:
            domain = load_domain(path)
        except DomainError as exc:
            refused.append(name)
            print(f"{name:<21} refused: {' '.join(str(exc).split())}", flush=True)
            continue
        for label, size in (("default", default_size(domain)),
                            (f"d/{FINE_DIVISOR}", diameter(domain) / FINE_DIVISOR)):
            a = _attempt(ours, domain, size, args.repeat, args.time_limit)
            b = _attempt(peer, domain, size, args.repeat, args.time_limit)
            ratio = (f"{a['time'] / b['time']:>9.2f}" if "error" not in a and
                     "error" not in b and b["time"] > 0 else f"{'-':>9}")
            print(f"{name:<21} {size:>9.4g} | {_cells(OURS, a)} | {_cells(PEER, b)} | {ratio}",
                  flush=True)
            rows.append((name, label, a, b))
            if "error" not in a and a["share"] < 1.0:
                fallbacks.append(f"{name} ({label}): {a['problem']}")
            for side, r, columns in (("ours", a, OURS), ("gmsh", b, PEER)):
                if "error" in r and len(f"failed: {r['error']}") > _width(columns):
                    print(f"    {side} failed: {r['error']}")

    both = [(a, b) for _, _, a, b in rows if "error" not in a and "error" not in b]
    print(f"\n{len(parts)} parts, {len(refused)} refused on import"
          f"{' (' + ', '.join(refused) + ')' if refused else ''}; {len(rows)} part-sizes, "
          f"ours failed on {sum('error' in a for _, _, a, _ in rows)}, gmsh on "
          f"{sum('error' in b for _, _, _, b in rows)}; fully block-structured "
          f"{sum('error' not in a and a['share'] >= 1.0 for _, _, a, _ in rows)}/{len(rows)}; "
          f"of the {len(both)} both meshed: minSJ >= gmsh's "
          f"{sum(a['min_sj'] >= b['min_sj'] - SAME_QUALITY for a, b in both)}, "
          f"irregular <= gmsh's "
          f"{sum(a['irregular'] <= b['irregular'] for a, b in both)}, faster "
          f"{sum(a['time'] < b['time'] for a, b in both)}")
    if fallbacks:
        print("not fully block-structured:")
        for line in fallbacks:
            print(f"  {' '.join(line.split())}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
