"""The parametric QuadMesh object in a real FreeCAD: creation from sketches and faces in any
placement, following design edits, keeping the last mesh on a breaking edit, save/reload."""

from __future__ import annotations

import os
import tempfile
import unittest

import FreeCAD
import Part

from quadcnn_wb.freecad import make_quad_mesh
from quadcnn_wb.freecad.sketches import plate_with_hole

V = FreeCAD.Vector


def plate_sketch(doc, placement):
    """A 40 x 20 plate with a radius-5 hole; returns (sketch, width constraint, radius one)."""
    return plate_with_hole(doc, 40.0, 20.0, 5.0, placement)


class TestQuadMeshObject(unittest.TestCase):
    def setUp(self):
        self.doc = FreeCAD.newDocument("QuadCNNTest")
        self.placement = FreeCAD.Placement(V(10, -5, 3), FreeCAD.Rotation(V(1, 1, 0), 30))

    def tearDown(self):
        FreeCAD.closeDocument(self.doc.Name)

    def test_sketch_in_a_rotated_offset_placement(self):
        sk, _, _ = plate_sketch(self.doc, self.placement)
        mesh = make_quad_mesh(self.doc, sk)
        self.doc.recompute()
        self.assertTrue(mesh.isValid(), mesh.Status)
        self.assertEqual(mesh.Status, "ok")
        self.assertEqual(mesh.FemMesh.FaceCount, mesh.Quads)
        self.assertEqual(mesh.Singularities, 4)
        self.assertEqual(mesh.IrregularVertices, 4)
        self.assertGreater(mesh.MinScaledJacobian, 0.5)
        inverse = sk.Placement.inverse()
        local = [inverse.multVec(v) for v in mesh.FemMesh.Nodes.values()]
        self.assertLess(max(abs(p.z) for p in local), 1e-9)  # nodes lie in the sketch plane
        self.assertAlmostEqual(min(p.x for p in local), 0.0, places=9)
        self.assertAlmostEqual(max(p.x for p in local), 40.0, places=9)
        names = [mesh.FemMesh.getGroupName(g) for g in mesh.FemMesh.Groups]
        self.assertIn("Block0", names)
        self.assertIn("LOOP1", names)  # the hole's boundary nodes, for FEM constraints
        self.assertFalse(mesh.StreamlineWires.Shape.isNull())
        self.assertEqual(len(mesh.BlockFaces.Shape.Faces), mesh.Blocks)

    def test_follows_set_datum_and_keeps_the_last_mesh_on_a_breaking_edit(self):
        sk, width, radius = plate_sketch(self.doc, self.placement)
        mesh = make_quad_mesh(self.doc, sk, ElementSize=2.0)
        self.doc.recompute()
        before = mesh.Quads
        sk.setDatum(width, FreeCAD.Units.Quantity("60 mm"))
        self.doc.recompute()
        self.assertTrue(mesh.isValid(), mesh.Status)
        self.assertGreater(mesh.Quads, before)  # same element size, larger plate
        widened = mesh.Quads
        sk.setDatum(radius, FreeCAD.Units.Quantity("15 mm"))  # hole cuts the plate's edges
        self.doc.recompute()
        self.assertFalse(mesh.isValid())
        self.assertIn("intersect", mesh.Status)
        self.assertEqual(mesh.FemMesh.FaceCount, widened)  # last good mesh kept
        sk.setDatum(radius, FreeCAD.Units.Quantity("5 mm"))
        self.doc.recompute()
        self.assertTrue(mesh.isValid(), mesh.Status)
        self.assertEqual(mesh.Quads, widened)

    def test_face_of_a_partdesign_body(self):
        body = self.doc.addObject("PartDesign::Body", "Body")
        box = self.doc.addObject("PartDesign::AdditiveBox", "Box")
        body.addObject(box)
        box.Length, box.Width, box.Height = 30, 10, 5
        body.Placement = self.placement
        self.doc.recompute()
        top = max(range(len(box.Shape.Faces)), key=lambda i: box.Shape.Faces[i].Area)
        mesh = make_quad_mesh(self.doc, (box, f"Face{top + 1}"), ElementSize=2.5)
        self.doc.recompute()
        self.assertTrue(mesh.isValid(), mesh.Status)
        self.assertEqual(mesh.Quads, 12 * 4)  # a 30 x 10 rectangle at size 2.5
        self.assertEqual(mesh.IrregularVertices, 0)
        face = box.Shape.Faces[top].copy()
        face.Placement = body.Placement.multiply(face.Placement)  # the body-local face, placed
        for node in list(mesh.FemMesh.Nodes.values())[:20]:
            self.assertLess(face.distToShape(Part.Vertex(node))[0], 1e-7)

    def test_open_sketch_is_refused_with_a_message(self):
        sk = self.doc.addObject("Sketcher::SketchObject", "Open")
        sk.addGeometry(Part.LineSegment(V(0, 0, 0), V(10, 0, 0)))
        sk.addGeometry(Part.LineSegment(V(10, 0, 0), V(10, 10, 0)))
        self.doc.recompute()
        mesh = make_quad_mesh(self.doc, sk)
        self.doc.recompute()
        self.assertFalse(mesh.isValid())
        self.assertIn("open wire", mesh.Status)

    def test_save_close_reopen_and_regenerate(self):
        sk, width, _ = plate_sketch(self.doc, self.placement)
        mesh = make_quad_mesh(self.doc, sk, Method="numerical", TargetNodes=1500)
        self.doc.recompute()
        quads, name, sketch_name = mesh.Quads, mesh.Name, sk.Name
        path = os.path.join(tempfile.mkdtemp(), "plate.FCStd")
        self.doc.saveAs(path)
        FreeCAD.closeDocument(self.doc.Name)
        self.doc = FreeCAD.openDocument(path)
        again = self.doc.getObject(name)
        self.assertEqual(type(again.Proxy).__name__, "QuadMeshProxy")
        self.assertEqual((again.Quads, again.FemMesh.FaceCount), (quads, quads))
        self.assertEqual((again.Method, again.TargetNodes), ("numerical", 1500))
        sketch = self.doc.getObject(sketch_name)
        sketch.setDatum(width, FreeCAD.Units.Quantity("50 mm"))
        self.doc.recompute()
        self.assertTrue(again.isValid(), again.Status)
        self.assertNotEqual(again.Quads, quads)


class TestQuadMeshDocument(unittest.TestCase):
    def setUp(self):
        self.doc = FreeCAD.newDocument("QuadCNNDoc")

    def tearDown(self):
        FreeCAD.closeDocument(self.doc.Name)

    def test_embedded_model_survives_save_and_reload(self):
        import hashlib

        sk, _, _ = plate_sketch(self.doc, FreeCAD.Placement())
        folder = tempfile.mkdtemp()
        model = os.path.join(folder, "family.onnx")
        with open(model, "wb") as handle:
            handle.write(b"ONNX model bytes stand-in " * 100)  # the property embeds any file
        digest = hashlib.sha256(open(model, "rb").read()).hexdigest()
        mesh = make_quad_mesh(self.doc, sk, Model=model, ModelEntry="user:family",
                              Method="numerical")  # not a real model: never run it
        self.doc.recompute()
        name = mesh.Name
        path = os.path.join(folder, "with_model.FCStd")
        self.doc.saveAs(path)
        os.remove(model)  # the document must not depend on the original file
        FreeCAD.closeDocument(self.doc.Name)
        self.doc = FreeCAD.openDocument(path)
        again = self.doc.getObject(name)
        self.assertEqual(again.ModelEntry, "user:family")
        self.assertTrue(os.path.isfile(again.Model))
        self.assertEqual(hashlib.sha256(open(again.Model, "rb").read()).hexdigest(), digest)

    def test_ellipse_sketch_is_approximated_and_meshed(self):
        sk = self.doc.addObject("Sketcher::SketchObject", "Ellipse")
        sk.addGeometry(Part.Ellipse(V(0, 0, 0), 30, 12))
        self.doc.recompute()
        mesh = make_quad_mesh(self.doc, sk, ElementSize=2.0)
        self.doc.recompute()
        self.assertTrue(mesh.isValid(), mesh.Status)
        self.assertEqual(mesh.IrregularVertices, mesh.Singularities)
        area = sum(f.Area for f in mesh.BlockFaces.Shape.Faces)
        self.assertAlmostEqual(area / (3.141592653589793 * 30 * 12), 1.0, delta=0.01)

    def test_a_bspline_edge_becomes_tangent_arcs_as_the_importer_makes_them(self):
        # The same rule as STEP/BREP input (core.input.arc_splines): no polyline kinks.
        from quadcnn_wb.core.input.corners import interior_angle, is_corner
        from quadcnn_wb.freecad.geometry import face_to_domain

        spline = Part.BSplineCurve()
        spline.interpolate([V(40, 0, 0), V(34, 9, 0), V(20, 14, 0), V(6, 9, 0), V(0, 0, 0)])
        wire = Part.Wire([Part.LineSegment(V(0, 0, 0), V(40, 0, 0)).toShape(),
                          spline.toShape()])
        placement = FreeCAD.Placement(V(10, -5, 3), FreeCAD.Rotation(V(1, 1, 0), 30))
        face = Part.Face(wire)
        face.Placement = placement
        domain = face_to_domain(face, placement)
        loop = domain.loops[0]
        arcs = [c for c in loop if c.kind == "arc"]
        self.assertGreaterEqual(len(arcs), 2)
        joints = [interior_angle(loop[k - 1], loop[k]) for k in range(len(loop))]
        self.assertEqual(sum(is_corner(a) for a in joints), 2)  # the line's two ends only
        self.assertAlmostEqual(domain.area / face.Area, 1.0, delta=1e-4)


    def test_a_bspline_edge_run_against_its_parameter_keeps_its_pieces_in_order(self):
        # The spline runs from (0, 0) to (40, 0); the wire takes it back from (40, 0),
        # after three lines.
        # Its pieces, each turned on its own, came in reversed order: a gap inside the edge.
        from quadcnn_wb.freecad.geometry import face_to_domain

        spline = Part.BSplineCurve()
        spline.interpolate([V(0, 0, 0), V(6, 9, 0), V(20, 14, 0), V(34, 9, 0), V(40, 0, 0)])
        corners = [V(0, 0, 0), V(0, -10, 0), V(40, -10, 0), V(40, 0, 0)]
        wire = Part.Wire([Part.LineSegment(a, b).toShape() for a, b in zip(corners, corners[1:])]
                         + [spline.toShape()])
        face = Part.Face(wire)
        domain = face_to_domain(face, FreeCAD.Placement())
        self.assertAlmostEqual(domain.area / face.Area, 1.0, delta=1e-4)
        self.assertFalse([note for note in domain.healed if "gap" in note])

    def test_edges_that_end_off_their_shared_vertex_are_joined_there(self):
        # The fan hub of pythonocc's Ventilator.stp (tests/corpus): the hexagonal bore's
        # edges end 0.014 mm off the vertices they share; the importer's rule, here too.
        from quadcnn_wb.freecad.geometry import _plane_placement, face_to_domain

        corpus = os.path.join(os.path.dirname(__file__), "..", "..", "..", "tests", "corpus")
        face = Part.read(os.path.join(corpus, "ventilator_hub.brep")).Faces[0]
        domain = face_to_domain(face, _plane_placement(face, "hub"))
        self.assertTrue(any("onto the vertex they share" in note for note in domain.healed),
                        domain.healed)
        # (its 39 B-spline edges are arc splines within 1e-4 of the hub's size)
        self.assertAlmostEqual(domain.area / face.Area, 1.0, delta=1e-3)


class TestSketchInBody(unittest.TestCase):
    def test_sketch_inside_a_placed_body_meshes_in_global_coordinates(self):
        doc = FreeCAD.newDocument("QuadCNNBody")
        try:
            body = doc.addObject("PartDesign::Body", "Body")
            body.Placement = FreeCAD.Placement(V(100, 20, 0), FreeCAD.Rotation(V(0, 0, 1), 90))
            sk, _, _ = plate_sketch(doc, FreeCAD.Placement(V(0, 0, 50), FreeCAD.Rotation()))
            body.addObject(sk)
            doc.recompute()
            mesh = make_quad_mesh(doc, sk, ElementSize=2.0)
            doc.recompute()
            self.assertTrue(mesh.isValid(), mesh.Status)
            inverse = sk.getGlobalPlacement().inverse()
            local = [inverse.multVec(v) for v in mesh.FemMesh.Nodes.values()]
            self.assertLess(max(abs(p.z) for p in local), 1e-9)
            self.assertAlmostEqual(max(p.x for p in local), 40.0, places=9)
            zs = {round(v.z, 9) for v in mesh.FemMesh.Nodes.values()}
            self.assertEqual(zs, {50.0})
        finally:
            FreeCAD.closeDocument(doc.Name)


class TestFemAnalysis(unittest.TestCase):
    def test_bundled_plate_analysis_matches_the_concentration_factor(self):
        from quadcnn_wb.freecad.environment import resource_path
        from quadcnn_wb.freecad.fem_example import solve

        doc = FreeCAD.openDocument(resource_path("examples", "plate_tension.FCStd"))
        try:
            mesh = doc.getObject("QuadMesh")
            mesh.touch()
            doc.recompute()
            self.assertTrue(mesh.isValid(), mesh.Status)
            result = solve(doc)
            self.assertLess(abs(result["error"]), 0.05, result)
        finally:
            FreeCAD.closeDocument(doc.Name)


class TestUndo(unittest.TestCase):
    def test_undoing_a_breaking_edit_restores_a_valid_mesh(self):
        doc = FreeCAD.newDocument("QuadCNNUndo")
        try:
            doc.UndoMode = 1
            sk, _, radius = plate_sketch(doc, FreeCAD.Placement())
            mesh = make_quad_mesh(doc, sk, ElementSize=2.0)
            doc.recompute()
            good = mesh.Quads
            doc.openTransaction("break the hole")
            sk.setDatum(radius, FreeCAD.Units.Quantity("15 mm"))
            doc.commitTransaction()
            doc.recompute()
            self.assertFalse(mesh.isValid())
            doc.undo()
            doc.recompute()
            self.assertEqual(sk.getDatum(radius).Value, 5.0)
            mesh.touch()
            doc.recompute()
            self.assertTrue(mesh.isValid(), mesh.Status)
            self.assertEqual((mesh.Quads, mesh.Status), (good, "ok"))
        finally:
            FreeCAD.closeDocument(doc.Name)
