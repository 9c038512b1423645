"""FreeCAD side of QuadCNN: everything that imports FreeCAD lives under this package."""


def make_quad_mesh(doc, source, name="QuadMesh", **properties):
    """A parametric QuadCNN mesh (Fem::FemMeshObjectPython) of a sketch or planar face."""
    from .mesh_object import make_quad_mesh as make

    return make(doc, source, name=name, **properties)
