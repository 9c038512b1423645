"""Tests that need a running FreeCAD; the TestQuadCNN module collects them."""
