"""How a QuadCNN mesh shows in the 3D view (GUI only).

A Fem::FemMeshObjectPython gets no display mode unless its view provider proxy names a
default one, and then draws nothing; this proxy asks for faces with their quad edges.
"""

from __future__ import annotations

from .environment import resource_path


class Stateless:
    """Proxies keep nothing worth saving: FreeCAD 0.20 pickles with __getstate__ and
    __setstate__, 0.21+ with dumps/loads; all of them say so."""

    def __getstate__(self):
        return None

    def __setstate__(self, state):
        return None

    def dumps(self):
        return None

    def loads(self, state):
        return None


class ViewProviderQuadMesh(Stateless):
    def __init__(self, vobj):
        vobj.Proxy = self

    def attach(self, vobj):
        self.Object = vobj.Object

    def getDefaultDisplayMode(self):
        return "Faces & Wireframe"

    def getIcon(self):
        return resource_path("icons", "QuadCNN_CreateMesh.svg")

    def claimChildren(self):
        obj = getattr(self, "Object", None)
        return [c for c in (getattr(obj, "StreamlineWires", None),
                            getattr(obj, "BlockFaces", None)) if c is not None]
