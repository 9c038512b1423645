"""Cut one planar face out of a public CAD file, exactly as the CAD kernel delivers it.

The corpus in this folder tests the importer and the mesher on faces from real parts, so
nothing here repairs or simplifies anything: circles stored as several arcs, tiny gaps,
B-spline edges, seam vertices all stay as Part.read gave them.  The face is written with
``face.exportBrep`` (one TopoDS_Face in a BREP file).

    .venv/bin/python tests/corpus/extract_face.py FILE --list
    .venv/bin/python tests/corpus/extract_face.py FILE [--face N] -o tests/corpus/NAME.brep

(any Python that imports FreeCAD 0.20: /usr/lib/freecad-python3/lib is put on sys.path;
``freecadcmd`` itself cannot pass options to a script).
``--list`` prints every planar face: its index in ``shape.Faces``, area, wires, edges and
edge kinds.  Without ``--face`` the chosen face is the planar face with the most edges
that has at least one hole or curved edge, the larger one on a tie.
"""

from __future__ import annotations

import argparse
import collections
import os
import sys

if "/usr/lib/freecad-python3/lib" not in sys.path:
    sys.path.append("/usr/lib/freecad-python3/lib")

import FreeCAD  # noqa: E402,F401  (Part needs FreeCAD loaded first)
import Part  # noqa: E402


def is_planar(face) -> bool:
    return type(face.Surface).__name__ == "Plane"


def edge_kinds(face) -> collections.Counter:
    return collections.Counter(type(e.Curve).__name__ for e in face.Edges)


def describe(k, face) -> str:
    kinds = ", ".join(f"{n} {kind}" for kind, n in sorted(edge_kinds(face).items()))
    return (f"face {k:>4}: area {face.Area:>12.4f}  wires {len(face.Wires):>3}  "
            f"edges {len(face.Edges):>4}  ({kinds})")


def interesting(face) -> bool:
    return len(face.Wires) > 1 or any(kind != "Line" for kind in edge_kinds(face))


def choose(faces):
    planar = [(k, f) for k, f in enumerate(faces) if is_planar(f) and interesting(f)]
    if not planar:
        raise SystemExit("no planar face with a hole or a curved edge")
    return max(planar, key=lambda kf: (len(kf[1].Edges), kf[1].Area))[0]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("input", help="STEP, BREP or IGES file")
    parser.add_argument("--list", action="store_true", help="list the planar faces")
    parser.add_argument("--face", type=int, help="index in shape.Faces (see --list)")
    parser.add_argument("-o", "--output", help="the face's BREP file")
    args = parser.parse_args(argv)
    shape = Part.read(args.input)
    faces = shape.Faces
    if args.list:
        print(f"{args.input}: {len(faces)} faces, "
              f"{sum(map(is_planar, faces))} planar")
        for k, face in enumerate(faces):
            if is_planar(face):
                print(describe(k, face))
        return 0
    k = choose(faces) if args.face is None else args.face
    face = faces[k]
    if not is_planar(face):
        raise SystemExit(f"face {k} is a {type(face.Surface).__name__}, not a plane")
    if not args.output:
        raise SystemExit("give -o OUT.brep (or --list)")
    face.exportBrep(args.output)
    print(f"{args.output}: {describe(k, face)}, {os.path.getsize(args.output)} bytes")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
