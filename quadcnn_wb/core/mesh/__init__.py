"""Mesh stage: quads in the blocks and free faces, gmsh's fallback, quality, export."""
