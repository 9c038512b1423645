"""Layout stage: from traced streamlines to blocks (T-mesh, segment counts, cuts)."""
