"""Design variants of a real sketch: dimensions varied within their ranges by the real
sketcher solver, the topology kept, the user's sketch left alone, the same for a seed."""

from __future__ import annotations

import unittest

import FreeCAD

from quadcnn_wb.core.input.domain import domain_from_json
from quadcnn_wb.freecad.design_variants import dimensions, make_variants
from quadcnn_wb.freecad.sketches import plate_with_hole
from quadcnn_wb.infer.signature import topology_signature


class TestDesignVariants(unittest.TestCase):
    def setUp(self):
        self.doc = FreeCAD.newDocument("QuadCNNVariantsTest")
        self.sketch, self.width, self.radius = plate_with_hole(self.doc, 40.0, 20.0, 5.0)

    def tearDown(self):
        FreeCAD.closeDocument(self.doc.Name)

    def test_dimensions_are_the_driving_ones(self):
        names = [d.name for d in dimensions(self.sketch)]
        self.assertEqual(names, ["Width", "Height", "HoleRadius"])

    def test_variants_stay_in_range_keep_topology_and_repeat(self):
        spread = {self.width: 0.2, self.radius: 0.2}
        domains, design = make_variants(self.sketch, 8, spread, seed=3)
        self.assertEqual(len(domains), 8)
        signature = topology_signature(design)
        widths = []
        for data in domains:
            domain = domain_from_json(data)
            self.assertEqual(topology_signature(domain), signature)
            widths.append(domain.bbox_max[0] - domain.bbox_min[0])
            self.assertAlmostEqual(domain.bbox_max[1] - domain.bbox_min[1], 20.0, places=6)
        self.assertAlmostEqual(widths[0], 40.0, places=6)  # the design itself comes first
        self.assertTrue(all(32.0 - 1e-6 <= w <= 48.0 + 1e-6 for w in widths))
        self.assertGreater(len(set(round(w, 6) for w in widths)), 4)
        again, _ = make_variants(self.sketch, 8, spread, seed=3)
        self.assertEqual(domains, again)
        self.assertAlmostEqual(self.sketch.getDatum("Width").Value, 40.0)
        self.assertNotIn("QuadCNNVariants", FreeCAD.listDocuments())
