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
        self._add_edge_lines(vobj)

    def _add_edge_lines(self, vobj):
        """The FEM view provider shades this face-only mesh but draws no quad edges; a line
        set above its display modes does."""
        from pivy import coin

        self.coords = coin.SoCoordinate3()
        self.lines = coin.SoIndexedLineSet()
        style = coin.SoDrawStyle()
        style.lineWidth = 1.0
        colour = coin.SoBaseColor()
        colour.rgb = (0.1, 0.1, 0.15)
        offset = coin.SoPolygonOffset()  # keep the lines in front of the shaded faces
        sep = coin.SoSeparator()
        for node in (offset, style, colour, self.coords, self.lines):
            sep.addChild(node)
        vobj.RootNode.addChild(sep)
        self.updateData(vobj.Object, "FemMesh")

    def updateData(self, obj, prop):
        if prop != "FemMesh" or not hasattr(self, "coords"):
            return
        mesh = obj.FemMesh
        nodes = mesh.Nodes
        ids = sorted(nodes)
        row = {n: i for i, n in enumerate(ids)}
        self.coords.point.setValues(0, len(ids), [tuple(nodes[n]) for n in ids])
        edges = set()
        for face in mesh.Faces:
            corners = mesh.getElementNodes(face)
            for k in range(len(corners)):
                a, b = corners[k], corners[(k + 1) % len(corners)]
                edges.add((min(a, b), max(a, b)))
        index = []
        for a, b in sorted(edges):
            index.extend((row[a], row[b], -1))
        self.lines.coordIndex.setValues(0, len(index), index)
        self.lines.coordIndex.setNum(len(index))

    def getDefaultDisplayMode(self):
        return "Faces & Wireframe"

    def getIcon(self):
        return resource_path("icons", "QuadCNN_CreateMesh.svg")

    def claimChildren(self):
        obj = getattr(self, "Object", None)
        return [c for c in (getattr(obj, "StreamlineWires", None),
                            getattr(obj, "BlockFaces", None)) if c is not None]
