"""Every part in a folder, meshed at the default size and at diameter / 100.

    python -m quadcnn_wb.bench.folder DIR [--rows ROWS.jsonl] [--compare EARLIER.jsonl]
                                          [--time-limit S] [--names NAME ...] [--gmsh]
                                          [--poses]

For faces nobody here wrote (a user's own parts, a held-out set of public CAD files): each
file (.brep .step .stp .iges .igs .json; JSON lists and objects without "loops", such as
a manifest or a mesh result, are skipped and named) and size runs in a fresh Python with a
time limit, so a hang or a crash costs that row only.  One line is printed per row and one
JSON line appended to ROWS (name, size_kind, structured_share, irregular_vertices,
min_scaled_jacobian, quads, longest_edge: the longest quad edge over the size asked for,
which shows a block whose counts ignore the size across it; mesh_s, wall_s, or error;
problem where some faces are no blocks, saying why; mesh_s is timed after one small part
meshed untimed in that process, wall_s is the whole process); then how many rows are all
in blocks per size.  With --compare, the rows that differ from an earlier ROWS file (share,
irregular vertices, errors, or the worst scaled Jacobian by more than 0.01) are listed:
what a change did to parts the tests do not hold.  With --gmsh, each row also holds gmsh's
quasi-structured algorithm (Mesh.Algorithm 11) on the same face at the same size (its
irregular vertices, worst scaled Jacobian, quads and seconds, by our own quality code), and
the summary counts the rows where ours is at least as good and faster: issue 15's bar, on
faces the tests do not hold.  With --poses, each face is also meshed (from its domain
JSON) in bench.families' five POSES (turned by odd angles, moved by 1e4 of its size,
mirrored, scaled by 1e-3 and 1e3) at the row's size scaled with it, and the row says
whether every copy got the same share, blocks, quads and irregular vertices
(``same_in_poses``, ``poses_differing``); the time limit then covers all six meshes.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import time
import traceback
from pathlib import Path

SUFFIXES = {".brep", ".step", ".stp", ".iges", ".igs", ".json"}
SIZES = ("default", "d100")
MARK = "@@ROW@@ "
SJ_CHANGE = 0.01  # a worst scaled Jacobian that moves by more is a difference


def worker(path: str, kind: str, peer: bool = False, poses: bool = False) -> int:
    """In the subprocess: mesh one file at one size (with gmsh alg. 11 if ``peer``; in
    every pose too if ``poses``), print one marked JSON row."""
    row: dict = {}
    try:
        from ..core.input.load import load_domain
        from ..core.input.pose import default_size, diameter
        from ..core.mesh.quality import longest_edge
        from ..core.pipeline import mesh_domain

        domain = load_domain(path)
        size = default_size(domain) if kind == "default" else diameter(domain) / 100.0
        if peer:
            row.update(_gmsh_row(domain, size))
        else:
            warm_up()
            start = time.perf_counter()
            result = mesh_domain(domain, size=size)
            row["mesh_s"] = round(time.perf_counter() - start, 3)
            row.update({
                "structured_share": float(result.structured_share),
                "irregular_vertices": int(result.quality["irregular_vertices"]),
                "min_scaled_jacobian": float(result.quality["min_scaled_jacobian"]),
                "quads": int(len(result.mesh.quads)),
                "longest_edge": round(longest_edge(result.mesh) / size, 3),
            })
            if result.problem:  # which faces are no blocks, and why
                row["problem"] = result.problem
            if poses:
                row.update(_pose_row(domain, size))
    except Exception as exc:  # a refused file is a row too, with its message
        row["error"] = f"{type(exc).__name__}: {exc}"
        row["traceback_tail"] = traceback.format_exc().strip().splitlines()[-3:]
    print(MARK + json.dumps(row), flush=True)
    return 0


# A plate with a hole: it takes every stage (singular points, tracing, the integer
# program), so the modules each stage loads on first use are loaded before the clock.
WARM_UP_PART = {"loops": [
    [{"line": [[0, 0], [2, 0]]}, {"line": [[2, 0], [2, 1]]}, {"line": [[2, 1], [0, 1]]},
     {"line": [[0, 1], [0, 0]]}],
    [{"circle": {"center": [1, 0.5], "radius": 0.25}}]]}


def warm_up() -> None:
    """Mesh a small part once, untimed, so that the row times the pipeline as a FreeCAD
    session or a batch macro runs it (its imports and gmsh's start paid once per
    process), as gmsh's row is timed on its meshing call alone.  Cold, a fresh process
    spent about 0.25 s more on a part meshed in 0.1 s."""
    from ..core.input.domain import domain_from_json
    from ..core.pipeline import mesh_domain

    mesh_domain(domain_from_json(WARM_UP_PART))


def _pose_row(domain, size: float) -> dict:
    """Whether the face's copies in every pose get the mesh its own JSON gets (the copies
    are made from that JSON, so the round trip is not what is compared)."""
    from ..core.input.domain import domain_from_json
    from ..core.pipeline import mesh_domain
    from .families import poses_differing

    data = domain.to_json()
    base = mesh_domain(domain_from_json(data), size=size)
    differing = poses_differing(data, base, size)
    return {"same_in_poses": not differing, "poses_differing": differing}


def _gmsh_row(domain, size: float) -> dict:
    """gmsh alg. 11's figures on the face (bench.corpus's peer, one run, no limit of its
    own: the process has one), under this file's row keys."""
    from .corpus import peer

    figures = peer(domain, size, 1, 0)
    return {"irregular_vertices": int(figures["irregular"]),
            "min_scaled_jacobian": float(figures["min_sj"]), "quads": int(figures["quads"]),
            "mesh_s": round(float(figures["time"]), 3)}


def run_one(path: Path, kind: str, limit: float, with_gmsh: bool = False,
            poses: bool = False) -> dict:
    """One row, from a fresh Python killed (with its children) after ``limit`` s; with
    gmsh's row under "gmsh", from a process of its own with the same limit."""
    row = {"name": path.stem, "size_kind": kind}
    row.update(_run_worker(path, kind, limit, ["poses"] if poses else []))
    if with_gmsh:
        row["gmsh"] = _run_worker(path, kind, limit, ["gmsh"])
        row["gmsh"].pop("wall_s")
    return row


def _run_worker(path: Path, kind: str, limit: float, extra: list) -> dict:
    row = {}
    start = time.perf_counter()
    command = [sys.executable, "-m", __spec__.name, "--worker", str(path), kind, *extra]
    proc = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)
    try:
        out, err = proc.communicate(timeout=limit or None)
    except subprocess.TimeoutExpired:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        proc.communicate()
        row.update(wall_s=round(time.perf_counter() - start, 3), error="timeout")
        return row
    row["wall_s"] = round(time.perf_counter() - start, 3)
    marked = [line for line in out.splitlines() if line.startswith(MARK)]
    if marked:
        row.update(json.loads(marked[-1][len(MARK):]))
    else:
        row["error"] = f"crash rc={proc.returncode}: " + \
            (err.strip().splitlines() or ["(no output)"])[-1]
    return row


def describe(row) -> str:
    if row is None:
        return "(missing)"
    if "error" in row:
        return f"error: {row['error'][:70]}"
    text = (f"share {row['structured_share']:.3f} irr {row['irregular_vertices']} "
            f"sj {row['min_scaled_jacobian']:.3f} quads {row['quads']}")
    if "longest_edge" in row:  # (rows written before it was measured have none)
        text += f" edge {row['longest_edge']:.1f}"
    if "same_in_poses" in row:
        text += " poses: same" if row["same_in_poses"] else \
            f" poses: differ in {row['poses_differing']}"
    peer = row.get("gmsh")
    if peer is None:
        return text
    if "error" in peer:
        return text + f" | gmsh error: {peer['error'][:40]}"
    return text + (f" {row['mesh_s']:.2f}s | gmsh irr {peer['irregular_vertices']} "
                   f"sj {peer['min_scaled_jacobian']:.3f} quads {peer['quads']} "
                   f"{peer['mesh_s']:.2f}s")


def load_rows(path) -> dict:
    """(name, size_kind) -> row; a pair written twice counts with its last row."""
    rows = {}
    for line in Path(path).read_text().splitlines():
        if line.strip():
            row = json.loads(line)
            rows[(row["name"], row["size_kind"])] = row
    return rows


def holds_a_part(path: Path) -> bool:
    """False for a JSON file that is plainly something else (a list, such as the
    corpus's manifest, or an object without "loops": a mesh result the command line
    wrote); a file that does not parse is a part, whose row then names what is wrong
    with it."""
    if path.suffix.lower() != ".json":
        return True
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return True
    return isinstance(data, dict) and "loops" in data


def differs(a, b) -> bool:
    if a is None or b is None or ("error" in a) != ("error" in b):
        return True
    if "error" in a:
        return a["error"] != b["error"]
    return (a["structured_share"] != b["structured_share"]
            or a["irregular_vertices"] != b["irregular_vertices"]
            or abs(a["min_scaled_jacobian"] - b["min_scaled_jacobian"]) > SJ_CHANGE)


def summary(rows: dict) -> list:
    """Per size: 'KIND: all in blocks N/M (E errors)'."""
    lines = []
    for kind in SIZES:
        sel = [r for (_, k), r in rows.items() if k == kind]
        if sel:
            full = sum(r.get("structured_share") == 1.0 for r in sel)
            errors = sum("error" in r for r in sel)
            lines.append(f"{kind}: all in blocks {full}/{len(sel)} ({errors} errors)")
            both = [r for r in sel
                    if "error" not in r and "error" not in r.get("gmsh", {"error": ""})]
            if both:
                lines.append(f"{kind}: of the {len(both)} gmsh alg. 11 meshed too: "
                             f"{_at_least_as_good(both)}")
            posed = [r for r in sel if "same_in_poses" in r]
            if posed:
                same = sum(r["same_in_poses"] for r in posed)
                lines.append(f"{kind}: the same in every pose {same}/{len(posed)}")
    return lines


def _at_least_as_good(rows) -> str:
    """Issue 15's bar, counted: worst element, irregular vertices, time against gmsh's."""
    sj = sum(r["min_scaled_jacobian"] >= r["gmsh"]["min_scaled_jacobian"] for r in rows)
    irr = sum(r["irregular_vertices"] <= r["gmsh"]["irregular_vertices"] for r in rows)
    faster = sum(r["mesh_s"] < r["gmsh"]["mesh_s"] for r in rows)
    every = sum(r["structured_share"] == 1.0
                and r["min_scaled_jacobian"] >= r["gmsh"]["min_scaled_jacobian"]
                and r["irregular_vertices"] <= r["gmsh"]["irregular_vertices"]
                and r["mesh_s"] < r["gmsh"]["mesh_s"] for r in rows)
    return (f"minSJ >= gmsh's {sj}, irregular <= gmsh's {irr}, faster {faster}; "
            f"all in blocks and all three {every}")


def comparison(earlier: dict, now: dict) -> list:
    """The rows run now that differ from the earlier run, each as two lines."""
    lines = []
    for key in sorted(now, key=lambda nk: (nk[1], nk[0])):
        if differs(earlier.get(key), now.get(key)):
            lines.append(f"{key[0]:40s} {key[1]:8s} before: {describe(earlier.get(key))}")
            lines.append(f"{'':40s} {'':8s} now:    {describe(now.get(key))}")
    return lines


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) in (3, 4) and argv[0] == "--worker":
        return worker(argv[1], argv[2], peer=argv[3:] == ["gmsh"],
                      poses=argv[3:] == ["poses"])
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", type=Path)
    parser.add_argument("--rows", type=Path, help="append one JSON line per row here")
    parser.add_argument("--compare", type=Path, help="an earlier --rows file")
    parser.add_argument("--time-limit", type=float, default=300.0,
                        help="seconds allowed to one file at one size (0: none)")
    parser.add_argument("--names", nargs="+", help="only these files (names without suffix)")
    parser.add_argument("--gmsh", action="store_true",
                        help="mesh each face with gmsh's Mesh.Algorithm 11 too and compare")
    parser.add_argument("--poses", action="store_true",
                        help="also mesh each face turned, moved, mirrored and rescaled, "
                             "and say whether every copy gets the same mesh")
    args = parser.parse_args(argv)
    files = sorted(p for p in args.folder.iterdir() if p.suffix.lower() in SUFFIXES)
    others = [p for p in files if not holds_a_part(p)]
    if others:
        print(f"skipped (JSON of something else: no 'loops'): "
              f"{', '.join(p.name for p in others)}", flush=True)
    files = [p for p in files if p not in others]
    if args.names:
        files = [p for p in files if p.stem in set(args.names)]
    if not files:
        print(f"{args.folder}: no part files ({', '.join(sorted(SUFFIXES))})", file=sys.stderr)
        return 2
    rows = {}
    for path in files:
        for kind in SIZES:
            row = run_one(path, kind, args.time_limit, args.gmsh, args.poses)
            rows[(row["name"], kind)] = row
            if args.rows:
                with open(args.rows, "a") as fh:
                    fh.write(json.dumps(row) + "\n")
            print(f"{row['name']:40s} {kind:8s} {row['wall_s']:7.1f}s  {describe(row)}",
                  flush=True)
    print("\n".join(summary(rows)))
    if args.compare:
        lines = comparison(load_rows(args.compare), rows)
        print(f"\n{len(lines) // 2} rows differ from {args.compare}")
        print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
