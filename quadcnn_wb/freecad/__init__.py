"""FreeCAD side of QuadCNN: everything that imports FreeCAD lives under this package."""
