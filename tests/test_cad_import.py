"""STEP/BREP/IGES input through gmsh's OpenCASCADE reader: written here by gmsh, read back."""

from __future__ import annotations

import math

import gmsh
import numpy as np
import pytest

from quadcnn_wb.core.field.background import background_mesh
from quadcnn_wb.core.gmsh_session import gmsh_session, silenced_stdio
from quadcnn_wb.core.input.curves import loop_signed_area
from quadcnn_wb.core.input.domain import DomainError
from quadcnn_wb.core.input.load import load_domain

PLATE_AREA = 2.0 - math.pi * 0.25**2


def write_cad(path, build):
    """Build OCC shapes with ``build(occ)`` and write them to ``path`` with gmsh."""
    with gmsh_session(), silenced_stdio():
        build(gmsh.model.occ)
        gmsh.model.occ.synchronize()
        gmsh.write(str(path))
    return path


def plate_with_hole(occ):
    plate = occ.addRectangle(0, 0, 0, 2, 1)
    hole = occ.addDisk(1, 0.5, 0, 0.25, 0.25)
    occ.cut([(2, plate)], [(2, hole)])


@pytest.mark.parametrize("suffix", [".step", ".brep", ".iges"])
def test_plate_with_hole_round_trip(tmp_path, suffix):
    domain = load_domain(write_cad(tmp_path / f"plate{suffix}", plate_with_hole))
    assert [[c.kind for c in loop] for loop in domain.loops] == [["line"] * 4, ["circle"]]
    hole = domain.loops[1][0]
    assert hole.center == pytest.approx(np.array([1.0, 0.5]), abs=1e-6)
    assert hole.radius == pytest.approx(0.25, rel=1e-6)
    assert domain.area == pytest.approx(PLATE_AREA, rel=1e-6)
    mesh = background_mesh(domain, nodes=800)
    assert abs(mesh.n_nodes - 800) <= 40


def test_face_in_a_tilted_plane_maps_to_its_plane_coordinates(tmp_path):
    def tilted(occ):
        plate_with_hole(occ)
        occ.rotate(occ.getEntities(2), 0, 0, 0, 1, 1, 0, 0.7)
        occ.translate(occ.getEntities(2), 5, -2, 3)

    domain = load_domain(write_cad(tmp_path / "tilted.step", tilted))
    assert domain.area == pytest.approx(PLATE_AREA, rel=1e-9)
    assert domain.loops[1][0].radius == pytest.approx(0.25, rel=1e-9)


def test_arcs_stay_arcs(tmp_path):
    def slot(occ):
        occ.addRectangle(0, 0, 0, 3, 1, roundedRadius=0.3)

    domain = load_domain(write_cad(tmp_path / "slot.step", slot))
    kinds = sorted(c.kind for c in domain.loops[0])
    assert kinds == ["arc"] * 4 + ["line"] * 4
    assert domain.area == pytest.approx(3.0 - (4 - math.pi) * 0.09, rel=1e-9)
    for arc in (c for c in domain.loops[0] if c.kind == "arc"):
        assert arc.radius == pytest.approx(0.3, rel=1e-9)


def test_first_planar_face_of_a_solid(tmp_path):
    domain = load_domain(write_cad(tmp_path / "box.step", lambda occ: occ.addBox(0, 0, 0, 1, 2, 3)))
    assert domain.area in (pytest.approx(2.0), pytest.approx(3.0), pytest.approx(6.0))


def test_spline_edges_become_arcs_and_lines_that_follow_them(tmp_path):
    # A polyline would follow the spline as well, but gmsh must put a node on each of its
    # vertices: a gear's sampled flanks made a 2048-node background impossible.
    from quadcnn_wb.core.input.arc_splines import CURVE_TOLERANCE
    from quadcnn_wb.core.input.corners import interior_angle
    from quadcnn_wb.core.input.features import is_smooth_join

    def blob(occ):
        pts = [occ.addPoint(x, y, 0) for x, y in [(0, 0), (2, -0.3), (3, 1), (1, 2), (-0.5, 1)]]
        curve = occ.addBSpline(pts + [pts[0]])
        occ.addPlaneSurface([occ.addCurveLoop([curve])])

    path = write_cad(tmp_path / "blob.step", blob)
    loop = load_domain(path).loops[0]
    assert any(c.kind == "arc" for c in loop) and 4 <= len(loop) <= 64
    assert all(is_smooth_join(interior_angle(a, b)) for a, b in zip(loop, loop[1:] + loop[:1]))
    with gmsh_session(), silenced_stdio():
        gmsh.model.occ.importShapes(str(path))
        gmsh.model.occ.synchronize()
        (_, tag), = gmsh.model.getEntities(1)
        lo, hi = gmsh.model.getParametrizationBounds(1, tag)
        xyz = gmsh.model.getValue(1, tag, list(np.linspace(lo[0], hi[0], 2001)))
    samples = np.reshape(xyz, (-1, 3))[:, :2]
    span = float(np.ptp(samples, axis=0).max())
    off = [min(np.hypot(*(p - c.point(c.project(p)))) for c in loop) for p in samples]
    assert max(off) <= 2 * CURVE_TOLERANCE * span  # (a face in XY keeps its x and y)


def test_many_small_spline_edges_keep_their_loop_closed(tmp_path):
    # A knurled ring (held-out AnalysisSitus 0078): hundreds of B-spline bumps far
    # smaller than the part.  Sampled within 1e-4 of their own span, each became pieces
    # shorter than the crumbs healing drops (1e-4 of the part), all were dropped, and the
    # loop was refused as open; pieces are now at least 4e-4 of the part long.
    bumps, radius, depth = 120, 0.05, 0.001

    def knurled_hole(occ):
        plate = occ.addRectangle(-10, -5, 0, 20, 10)
        points = []
        for k in range(3 * bumps):
            a = 2 * math.pi * k / (3 * bumps)
            r = radius + (depth if k % 3 == 1 else 0.0)
            points.append(occ.addPoint(r * math.cos(a), r * math.sin(a), 0))
        curves = [occ.addBSpline([points[3 * k], points[3 * k + 1],
                                  points[(3 * k + 3) % len(points)]])
                  for k in range(bumps)]
        hole = occ.addPlaneSurface([occ.addCurveLoop(curves)])
        occ.cut([(2, plate)], [(2, hole)])

    domain = load_domain(write_cad(tmp_path / "knurled.brep", knurled_hole))
    hole = domain.loops[1]
    # Each bump is a piece or two, none dropped, and the hole is not merged into chords:
    # joint by joint the bumps look collinear within the healing tolerance, and merging
    # them one after another made the hole a triangle.
    assert bumps <= len(hole) <= 2 * bumps
    assert abs(loop_signed_area(hole)) == pytest.approx(math.pi * radius**2, rel=0.05)


def test_non_planar_file_is_refused(tmp_path):
    path = write_cad(tmp_path / "ball.step", lambda occ: occ.addSphere(0, 0, 0, 1))
    with pytest.raises(DomainError, match="no planar face"):
        load_domain(path)


@pytest.mark.parametrize("content, message", [
    (b"", "the file is empty"),
    (b"this is not a STEP file\n", "cannot read as STEP"),
    (None, "cannot read as STEP"),  # truncated
])
def test_corrupt_files_are_refused(tmp_path, content, message):
    if content is None:
        full = write_cad(tmp_path / "full.step", plate_with_hole).read_bytes()
        content = full[: len(full) // 3]
    path = tmp_path / "bad.step"
    path.write_bytes(content)
    with pytest.raises(DomainError, match=message):
        load_domain(path)
    assert not gmsh.isInitialized()


def test_missing_file(tmp_path):
    with pytest.raises(DomainError, match="no such file"):
        load_domain(tmp_path / "nothing.step")


def test_a_spline_whose_derivative_vanishes_at_its_ends_imports_cleanly(tmp_path):
    # Doubled end control points: the B-spline's derivative is zero at both ends, so
    # the biarcs take their end tangents from the samples (a zero tangent gave NaN arcs).
    import warnings

    def flap(occ):
        a, b, c = occ.addPoint(0, 0, 0), occ.addPoint(10, 0, 0), occ.addPoint(10, 5, 0)
        inner = [occ.addPoint(4, 6, 0), occ.addPoint(2, 3, 0)]
        spline = occ.addBSpline([c, c, *inner, a, a])
        occ.addPlaneSurface([occ.addCurveLoop([occ.addLine(a, b), occ.addLine(b, c), spline])])

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        domain = load_domain(write_cad(tmp_path / "flap.brep", flap))
    loop = domain.loops[0]
    assert all(np.all(np.isfinite(c.p0)) for c in loop) and domain.area > 0
    assert any(c.kind == "arc" for c in loop)


@pytest.mark.parametrize("name", ["crank_arm_web", "housing_rib"])
def test_a_turned_file_gives_the_same_curves(tmp_path, name):
    # The pieces' sizes and tolerances come from sizes a turned copy shares: with a
    # bounding box's, crank_arm_web turned by 37° got 32 pieces where its own pose got 34.
    from conftest import REPO

    def turned(angle):
        path = tmp_path / f"{name}_{angle}.brep"
        with gmsh_session(), silenced_stdio():
            gmsh.model.occ.importShapes(str(REPO / "tests" / "corpus" / f"{name}.brep"))
            gmsh.model.occ.synchronize()
            gmsh.model.occ.rotate(gmsh.model.getEntities(2), 3, -2, 0, 0, 0, 1,
                                  math.radians(angle))
            gmsh.model.occ.synchronize()
            gmsh.write(str(path))
        return load_domain(path)

    own, copy = turned(0), turned(37)
    assert [[c.kind for c in loop] for loop in copy.loops] == \
        [[c.kind for c in loop] for loop in own.loops]
    assert copy.area == pytest.approx(own.area, rel=1e-9)
