"""How a QuadCNN mesh shows in the 3D view (GUI only).

A Fem::FemMeshObjectPython gets no display mode unless its view provider proxy names a
default one, and then draws nothing; this proxy asks for faces with their quad edges,
colours each block, and marks the singular points (valence 3 blue, valence 5 red) — the
picture of the paper's figures, in the 3D view.
"""

from __future__ import annotations

from .environment import resource_path

# Distinct, light block colours (adjacent blocks rarely share one: ids run along the
# partition); singular points by valence.
BLOCK_COLOURS = ((0.65, 0.81, 0.89), (0.70, 0.87, 0.54), (0.99, 0.75, 0.44),
                 (0.79, 0.70, 0.84), (1.00, 1.00, 0.60), (0.98, 0.60, 0.60),
                 (0.55, 0.83, 0.78), (0.99, 0.80, 0.90), (0.85, 0.85, 0.85),
                 (0.74, 0.50, 0.74), (0.80, 0.92, 0.77), (1.00, 0.93, 0.44))
VALENCE_COLOURS = {3: (0.12, 0.30, 0.85), 5: (0.85, 0.10, 0.10)}


def overall_binding(coin):
    """One colour for the whole node: the FEM display's per-element colour binding leaks
    into siblings that follow it in the view provider's root."""
    binding = coin.SoMaterialBinding()
    binding.value = coin.SoMaterialBinding.OVERALL
    return binding


def marker_set(coin, points, colour):
    """Filled circles at points, in exactly `colour` whatever the scene's lighting."""
    sep = coin.SoSeparator()
    light = coin.SoLightModel()
    light.model = coin.SoLightModel.BASE_COLOR
    material = coin.SoMaterial()
    material.diffuseColor = colour
    material.emissiveColor = colour
    coords = coin.SoCoordinate3()
    coords.point.setValues(0, len(points), points)
    markers = coin.SoMarkerSet()
    markers.markerIndex = coin.SoMarkerSet.CIRCLE_FILLED_9_9
    for node in (light, overall_binding(coin), material, coords, markers):
        sep.addChild(node)
    return sep


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
        from pivy import coin

        self.Object = vobj.Object
        self.ViewObject = vobj
        # Our own nodes sit beside FEM's display-mode switch, which Visibility does not
        # reach: they get a switch of their own, kept in step in onChanged.
        self.extras = coin.SoSwitch()
        self.extras.whichChild = coin.SO_SWITCH_ALL
        vobj.RootNode.addChild(self.extras)
        self._add_singular_markers(vobj)
        self._add_edge_lines(vobj)

    def onChanged(self, vobj, prop):
        if prop == "Visibility" and hasattr(self, "extras"):
            from pivy import coin

            self.extras.whichChild = coin.SO_SWITCH_ALL if vobj.Visibility else \
                coin.SO_SWITCH_NONE

    def _add_singular_markers(self, vobj):
        from pivy import coin

        self.marks = coin.SoAnnotation()  # drawn last, over the faces, never hidden
        self.extras.addChild(self.marks)

    def _show_singular_points(self, obj):
        from pivy import coin

        self.marks.removeAllChildren()
        points = list(getattr(obj, "SingularPoints", []))
        valences = list(getattr(obj, "SingularValences", []))
        for valence, colour in VALENCE_COLOURS.items():
            chosen = [p for p, v in zip(points, valences) if v == valence]
            if not chosen:
                continue
            self.marks.addChild(marker_set(coin, [tuple(p) for p in chosen], colour))

    def _colour_blocks_soon(self, obj):
        """FEM rebuilds its display after this proxy hears of a new FemMesh, dropping any
        colours set now; so colour once the event loop is back."""
        try:
            from PySide import QtCore

            QtCore.QTimer.singleShot(0, lambda: self._colour_blocks(obj))
        except ImportError:
            self._colour_blocks(obj)

    def _colour_blocks(self, obj):
        mesh = obj.FemMesh
        colours = {}
        for group in mesh.Groups:
            name = mesh.getGroupName(group)
            if not name.startswith("Block") or mesh.getGroupElementType(group) != "Face":
                continue
            colour = BLOCK_COLOURS[int(name[5:]) % len(BLOCK_COLOURS)]
            for element in mesh.getGroupElements(group):
                colours[element] = colour
        try:
            self.ViewObject.ElementColor = colours
            self.block_colours = len(set(colours.values()))
        except (AttributeError, TypeError):  # a FEM build without per-element colours
            self.block_colours = 0

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
        for node in (offset, style, overall_binding(coin), colour, self.coords, self.lines):
            sep.addChild(node)
        self.extras.addChild(sep)
        self.updateData(vobj.Object, "FemMesh")

    def updateData(self, obj, prop):
        if prop == "SingularValences" and hasattr(self, "marks"):
            self._show_singular_points(obj)
        if prop != "FemMesh" or not hasattr(self, "coords"):
            return
        self._colour_blocks_soon(obj)
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

    def setEdit(self, vobj, mode=0):
        if mode != 0:
            return None
        from .task_panel import open_panel

        open_panel(vobj.Object)
        return True

    def unsetEdit(self, vobj, mode=0):
        import FreeCADGui

        FreeCADGui.Control.closeDialog()
        return True

    def doubleClicked(self, vobj):
        import FreeCADGui

        FreeCADGui.ActiveDocument.setEdit(vobj.Object.Name)
        return True

    def getDefaultDisplayMode(self):
        return "Faces & Wireframe"

    def getIcon(self):
        return resource_path("icons", "QuadCNN_CreateMesh.svg")

    def claimChildren(self):
        obj = getattr(self, "Object", None)
        return [c for c in (getattr(obj, "StreamlineWires", None),
                            getattr(obj, "BlockFaces", None)) if c is not None]
