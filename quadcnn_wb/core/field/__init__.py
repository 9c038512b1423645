"""Field stage: background triangle mesh, cross (frame) field, labels, the reference."""
