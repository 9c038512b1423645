"""The project's fixed layout and the import rules of DESIGN.md."""

from __future__ import annotations

import ast
import os
import xml.etree.ElementTree as ET

from conftest import REPO

FORBIDDEN_IN_CORE = {"FreeCAD", "FreeCADGui", "Part", "Sketcher", "Fem", "torch", "PySide",
                     "PySide2", "onnxruntime"}


def imported_modules(path):
    tree = ast.parse(path.read_text(), filename=str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            yield from (alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            yield node.module.split(".")[0]


def test_top_level_layout():
    for name in ["InitGui.py", "Init.py", "quadcnn_wb", "resources", "tests", "package.xml",
                 "README.md", "pyproject.toml", "Makefile", "LICENSE", "TestQuadCNN.py"]:
        assert (REPO / name).exists(), name
    assert os.access(REPO / ".ci" / "run", os.X_OK)
    assert "GNU LESSER GENERAL PUBLIC LICENSE" in (REPO / "LICENSE").read_text()[:200]
    assert "Version 2.1" in (REPO / "LICENSE").read_text()[:300]


def test_core_never_imports_freecad_torch_or_onnxruntime():
    for path in (REPO / "quadcnn_wb" / "core").rglob("*.py"):
        bad = set(imported_modules(path)) & FORBIDDEN_IN_CORE
        assert not bad, f"{path.name} imports {bad}"


def test_package_xml_is_an_addon_manager_workbench():
    ns = {"p": "https://wiki.freecad.org/Package_Metadata"}
    root = ET.parse(REPO / "package.xml").getroot()
    assert root.find("p:name", ns).text == "QuadCNN"
    assert root.find("p:license", ns).text == "LGPL-2.1-or-later"
    wb = root.find("p:content/p:workbench", ns)
    assert wb.find("p:classname", ns).text == "QuadCNNWorkbench"
    assert wb.find("p:subdirectory", ns).text == "./"
    assert wb.find("p:freecadmin", ns).text.startswith("0.20")
    icon = wb.find("p:icon", ns).text
    assert (REPO / icon).is_file() and (REPO / icon).read_text().lstrip().startswith("<?xml")
    deps = {d.text for d in wb.findall("p:depend", ns) if d.get("type") == "python"}
    assert {"gmsh", "onnxruntime", "numpy", "scipy"} <= deps


def test_readme_starts_with_the_two_commands():
    text = (REPO / "README.md").read_text()
    first_block = text[: text.index("make test") + 20]
    assert "make demo" in first_block and len(first_block) < 1500


def test_infer_never_imports_the_freecad_side():
    """FreeCAD hands infer its model folder (infer.user_folder), not the other way."""
    packages = {0: "", 1: "quadcnn_wb.infer.", 2: "quadcnn_wb."}
    for path in (REPO / "quadcnn_wb" / "infer").rglob("*.py"):
        tree = ast.parse(path.read_text(), filename=str(path))
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                names = [packages[node.level] + (node.module or "")]
            elif isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            else:
                continue
            assert not any(n.startswith("quadcnn_wb.freecad") for n in names), path.name


def test_a_split_whose_blocks_cannot_be_filled_is_left_whole_in_the_rebuild():
    # Spokes of a split odd face used to carry no origin, so a free face containing
    # them could never be dissolved: the rebuild met the same unfillable face every
    # round and the whole part fell back to gmsh (sketch_gear).  A pentagon with no
    # streamline is one five-cornered face: split round its centre, then left whole.
    from shapes import regular_polygon

    from quadcnn_wb.core.input.domain import domain_from_json
    from quadcnn_wb.core.layout.partition import build_partition

    domain = domain_from_json({"loops": [regular_polygon(5, 4.0)]})
    first = build_partition(domain, [], 1.0)
    splits = sorted({e.origin for e in first.edges if e.origin and e.origin[0] == "split"},
                    key=repr)
    assert len(splits) == 1 and len(first.blocks) == 5 and not first.free_faces
    again = build_partition(domain, [], 1.0, dissolve=frozenset(splits))
    assert splits[0] not in {e.origin for e in again.edges}
    assert any("whose split could not be filled" in f.reason for f in again.free_faces)
    assert not again.blocks


def test_a_separatrix_running_along_the_boundary_leaves_no_sliver_face():
    # A trace that meets the boundary at a glancing angle and runs on beside it a fraction
    # of an element off (nist_ctc_05's lettering) cut a face no quad fits in; it is the
    # boundary's own line there, so the partition drops it and keeps the blocks.
    import numpy as np

    from quadcnn_wb.core.input.domain import domain_from_json
    from quadcnn_wb.core.layout.partition import build_partition
    from quadcnn_wb.core.layout.streamlines import Endpoint, Streamline

    loop = [{"line": [[0, 0], [10, 0]]}, {"line": [[10, 0], [10, 4]]},
            {"line": [[10, 4], [0, 4]]}, {"line": [[0, 4], [0, 0]]}]
    domain = domain_from_json({"loops": [loop]})

    def line(points, start, end):
        return Streamline(np.array(points, float), Endpoint("boundary", loop=0, **start),
                          Endpoint("boundary", loop=0, **end))

    across = line([[5, 0], [5, 4]], dict(segment=0, param=0.5), dict(segment=2, param=0.5))
    glancing = line([[6, 0], [8, 0.03], [10, 0.05]], dict(segment=0, param=0.6),
                    dict(segment=1, param=0.0125))
    alone = build_partition(domain, [across], 1.0)
    both = build_partition(domain, [across, glancing], 1.0)
    assert (len(alone.blocks), len(alone.free_faces)) == (2, 0)
    assert (len(both.blocks), len(both.free_faces)) == (2, 0)
    assert not any(edge.streamline == 1 for edge in both.edges)
    # A strip a quarter element wide or more is a face of its own (here: a block).
    wide = line([[6, 0], [7, 0.4], [10, 0.4]], dict(segment=0, param=0.6),
                dict(segment=1, param=0.1))
    kept = build_partition(domain, [across, wide], 1.0)
    assert any(edge.streamline == 1 for edge in kept.edges)


def test_a_sliver_edge_that_another_line_ends_on_stays():
    # The glancing trace of the test above, but now another line ends on it (a T-junction
    # half way along): dropping the sliver's edge would leave that line hanging and the
    # face beyond turning back, so the sliver rule keeps it (the line is then a block
    # side, the strip a face of its own).  At element size 0.1 the strip (0.04 to 0 thick)
    # is under a quarter element wide, and the T end lies two tenths of an element off
    # the boundary, a place of its own.
    import numpy as np

    from quadcnn_wb.core.input.domain import domain_from_json
    from quadcnn_wb.core.layout.partition import build_partition
    from quadcnn_wb.core.layout.streamlines import Endpoint, Streamline

    loop = [{"line": [[0, 0], [10, 0]]}, {"line": [[10, 0], [10, 1]]},
            {"line": [[10, 1], [0, 1]]}, {"line": [[0, 1], [0, 0]]}]
    domain = domain_from_json({"loops": [loop]})
    xs = np.linspace(0.0, 9.9, 100)
    glancing = Streamline(np.column_stack([xs, 0.04 * (1 - xs / 9.9)]),
                          Endpoint("boundary", loop=0, segment=3, param=0.96),
                          Endpoint("boundary", loop=0, segment=0, param=0.99))
    half = float(np.hypot(*np.diff(glancing.points[:51], axis=0).T).sum())
    total = float(np.hypot(*np.diff(glancing.points, axis=0).T).sum())
    t_end = glancing.points[50]
    down = Streamline(np.array([[t_end[0], 1.0], t_end]),
                      Endpoint("boundary", loop=0, segment=2, param=1 - t_end[0] / 10),
                      Endpoint("streamline", 0, param=half / total))
    alone = build_partition(domain, [glancing], 0.1)
    assert not any(edge.streamline == 0 for edge in alone.edges)  # a sliver: it goes
    both = build_partition(domain, [glancing, down], 0.1)
    assert any(edge.streamline == 0 for edge in both.edges)
    assert any(edge.streamline == 1 for edge in both.edges)
    t_vertex = int(np.argmin(np.hypot(*(both.vertices - t_end).T)))
    assert np.hypot(*(both.vertices[t_vertex] - t_end)) < 1e-9
    assert sum(t_vertex in (edge.a, edge.b) for edge in both.edges) >= 3
