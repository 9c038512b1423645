"""FreeCAD side of QuadCNN: everything that imports FreeCAD lives under this package.

Importing it (FreeCAD's Init.py does, at start-up) tells the model registry, which never
imports FreeCAD, that user models live where the QuadCNN preferences say.
"""

from ..infer.user_folder import set_host_folder


def make_quad_mesh(doc, source, name="QuadMesh", **properties):
    """A parametric QuadCNN mesh (Fem::FemMeshObjectPython) of a sketch or planar face."""
    from .mesh_object import make_quad_mesh as make

    return make(doc, source, name=name, **properties)


def _preference_model_folder():
    """The preferences' model folder, read when asked for (it may have changed)."""
    from .preferences import user_model_folder

    return user_model_folder()


def _register_model_folder() -> None:
    try:
        import FreeCAD  # noqa: F401  (present only inside FreeCAD)
    except ImportError:
        return  # imported outside FreeCAD (for its environment helpers): no preferences
    set_host_folder(_preference_model_folder)


_register_model_folder()
