"""The workbench inside a real FreeCAD process: registration, dependencies, core pipeline."""

from __future__ import annotations

import math
import unittest

import FreeCAD

from quadcnn_wb.freecad import environment


class TestQuadCNNApp(unittest.TestCase):
    def test_registered_as_a_freecad_test_module(self):
        self.assertIn("TestQuadCNN", FreeCAD.__unit_test__)

    def test_workbench_folder_is_the_checkout(self):
        mod_dir = FreeCAD.getUserAppDataDir() + "Mod/QuadCNN"
        import os

        self.assertTrue(os.path.samefile(mod_dir, environment.REPO_ROOT),
                        f"{mod_dir} should link to {environment.REPO_ROOT}")

    def test_dependencies_import_without_environment_variables(self):
        import gmsh
        import onnxruntime

        self.assertTrue(gmsh.__version__.startswith("4."))
        self.assertTrue(onnxruntime.__version__)

    def test_background_mesh_runs_in_freecad(self):
        from quadcnn_wb.core.field.background import background_mesh
        from quadcnn_wb.core.input.load import load_domain

        domain = load_domain(environment.resource_path("examples", "plate_hole.json"))
        mesh = background_mesh(domain, nodes=1000)
        self.assertLessEqual(abs(mesh.n_nodes - 1000), 50)
        on_hole = mesh.boundary_nodes[mesh.boundary_loop == 1]
        radii = [math.hypot(x - 1.0, y - 0.5) for x, y in mesh.nodes[on_hole]]
        self.assertGreater(len(radii), 8)
        self.assertLess(max(abs(r - 0.25) for r in radii), 1e-12)

    def test_bad_input_is_a_clear_error(self):
        from quadcnn_wb.core.input.domain import DomainError, domain_from_json

        with self.assertRaisesRegex(DomainError, "loop 0.*open loop"):
            domain_from_json({"loops": [[{"line": [[0, 0], [1, 0]]},
                                         {"line": [[1, 0], [1, 1]]}]]})
