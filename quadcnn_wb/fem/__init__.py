"""Finite-element use of the quad meshes (CalculiX), to show they work for analysis."""
