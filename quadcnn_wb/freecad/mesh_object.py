"""The QuadCNN mesh as a FreeCAD document object: a Fem::FemMeshObjectPython whose proxy
runs the pipeline on its source sketch or face at every recompute.

No GUI code here (FreeCAD FEM layout: proxies hold logic, view providers live apart).  A
failing regeneration prints the reason with the object's name, sets Status, and raises,
which FreeCAD turns into an invalid-marked object; the FemMesh of the last good run is
left untouched, so a breaking design edit never loses the mesh.
"""

from __future__ import annotations

import json
import time

import FreeCAD

from .view_provider import Stateless

PROPERTIES = (
    # (type, name, group, tooltip)
    ("App::PropertyLinkSub", "Source", "QuadCNN", "Sketch or planar face to mesh"),
    ("App::PropertyEnumeration", "Method", "QuadCNN",
     "How streamlines are found: auto (a matching model, else numerical), cnn, numerical"),
    ("App::PropertyFileIncluded", "Model", "QuadCNN",
     "ONNX model embedded in the document (cnn method)"),
    ("App::PropertyString", "ModelEntry", "QuadCNN", "Registry entry the model came from"),
    ("App::PropertyInteger", "TargetNodes", "QuadCNN", "Background mesh node count"),
    ("App::PropertyLength", "ElementSize", "QuadCNN",
     "Target quad size (0: the source's diagonal / 40)"),
    ("App::PropertyBool", "Smoothing", "QuadCNN", "Smooth the mesh after the block maps"),
    ("App::PropertyLink", "Part", "QuadCNN",
     "The source's object, for FEM: CalculiX maps constraints through this link"),
    ("App::PropertyLink", "StreamlineWires", "QuadCNN", "Companion: streamlines as wires"),
    ("App::PropertyLink", "BlockFaces", "QuadCNN", "Companion: the blocks as faces"),
    ("App::PropertyInteger", "Blocks", "Results", "Number of blocks"),
    ("App::PropertyInteger", "Quads", "Results", "Number of quadrilaterals"),
    ("App::PropertyInteger", "Singularities", "Results", "Singular points of the field"),
    ("App::PropertyFloat", "MinScaledJacobian", "Results", "Worst element quality"),
    ("App::PropertyInteger", "IrregularVertices", "Results", "Irregular vertices"),
    ("App::PropertyString", "MethodUsed", "Results", "Method that produced the mesh"),
    ("App::PropertyIntegerList", "Fallbacks", "Results",
     "Streamlines the cnn path had to trace numerically"),
    ("App::PropertyString", "Timings", "Results", "Seconds per stage (JSON)"),
    ("App::PropertyString", "Status", "Results", "ok, or what went wrong last time"),
    ("App::PropertyFloat", "StructuredShare", "Results",
     "Share of the quads that lie in blocks (1: fully block-structured)"),
    ("App::PropertyStringList", "Healed", "Results",
     "What the input healing changed (joined gaps, merged arcs and lines)"),
    ("App::PropertyVectorList", "SingularPoints", "Results",
     "Singular points of the frame field (global coordinates)"),
    ("App::PropertyIntegerList", "SingularValences", "Results",
     "Valence of each singular point (3 or 5)"),
)
READ_ONLY = ("Blocks", "Quads", "Singularities", "MinScaledJacobian", "IrregularVertices",
             "MethodUsed", "Fallbacks", "Timings", "Status", "SingularPoints",
             "SingularValences", "ModelEntry", "StructuredShare", "Healed")
DEFAULTS = {"Method": ["auto", "cnn", "numerical"], "TargetNodes": 2048, "Smoothing": True}


def preferred_defaults(obj) -> None:
    """A new object starts from the user's preferences (Edit → Preferences → QuadCNN)."""
    from . import preferences

    obj.Method = preferences.method()
    obj.TargetNodes = preferences.target_nodes()
    obj.ElementSize = preferences.element_size()


def add_properties(obj) -> None:
    """Declare every property once; safe to call again (on restore, after upgrades)."""
    for kind, name, group, tip in PROPERTIES:
        if name in obj.PropertiesList:
            continue
        obj.addProperty(kind, name, group, tip)
        if name in DEFAULTS:
            setattr(obj, name, DEFAULTS[name])
        if name in READ_ONLY:
            obj.setEditorMode(name, 1)


class QuadMeshProxy(Stateless):
    Type = "QuadCNN::QuadMesh"

    def __init__(self, obj):
        obj.Proxy = self
        self.last_result = None  # the latest MeshResult, in memory only (not saved)
        add_properties(obj)

    def onDocumentRestored(self, obj):
        self.last_result = None
        add_properties(obj)
        if FreeCAD.GuiUp and obj.ViewObject is not None and obj.ViewObject.Proxy is None:
            from .view_provider import ViewProviderQuadMesh

            ViewProviderQuadMesh(obj.ViewObject)

    def execute(self, obj):
        from ..core.input.domain import DomainError
        from ..core.pipeline import mesh_domain
        from .geometry import face_to_domain, source_shape_and_placement, to_global
        from .mesh_builder import fem_mesh, update_companions

        started = time.perf_counter()
        progress = FreeCAD.Base.ProgressIndicator()
        progress.start(f"QuadCNN: meshing {obj.Label}", 0)
        try:
            source = source_of(obj)
            face, plane, placement = source_shape_and_placement(source)
            label = source[0].Label if isinstance(source, tuple) else source.Label
            domain = face_to_domain(face, plane, label)
            learned = _learned_source(obj, domain)
            size = float(obj.ElementSize) or None
            result = mesh_domain(domain, size=size, nodes=int(obj.TargetNodes),
                                 method=obj.Method, smoothing=bool(obj.Smoothing),
                                 learned_streamlines=learned)
        except (DomainError, ValueError, RuntimeError) as exc:
            message = " ".join(str(exc).split())
            obj.Status = f"error: {message}"
            FreeCAD.Console.PrintError(f"{obj.Label}: {message}\n")
            raise RuntimeError(f"{obj.Label}: {message}") from None
        finally:
            progress.stop()
        self.last_result = result
        obj.FemMesh = fem_mesh(result, placement)
        update_companions(obj, result, placement)
        q = result.quality
        obj.Blocks, obj.Quads = q["blocks"], q["quads"]
        singular = result.reference.field.singularities
        obj.Singularities = len(singular)
        obj.SingularPoints = to_global(placement, [s.xy.tolist() for s in singular])
        obj.SingularValences = [int(s.valence) for s in singular]
        obj.MinScaledJacobian = q["min_scaled_jacobian"]
        obj.IrregularVertices = q["irregular_vertices"]
        obj.MethodUsed = result.method
        obj.Fallbacks = list(result.fallback)
        obj.Timings = json.dumps({k: round(v, 4) for k, v in result.timings.items()})
        obj.StructuredShare = result.structured_share
        obj.Healed = list(domain.healed)
        healed = f" (input healed: {'; '.join(domain.healed)})" if domain.healed else ""
        obj.Status = ("ok" if result.structured else f"ok, but {result.problem}") + healed
        if not result.structured:
            FreeCAD.Console.PrintWarning(f"{obj.Label}: {result.problem}\n")
        FreeCAD.Console.PrintLog(f"{obj.Label}: {q['quads']} quads in "
                                 f"{time.perf_counter() - started:.2f} s\n")


def _learned_source(obj, domain):
    """The model's streamline source for this object, or None for numerical tracing.

    An embedded model (the Model property) wins; otherwise auto and cnn look in the user
    model folder and the shipped models for one trained on the domain's topology, and the
    one found is named in ModelEntry.
    """
    from ..infer.cnn import cnn_streamlines
    from . import preferences

    if obj.Method == "numerical":
        return None
    if obj.Model:
        obj.ModelEntry = "embedded"
        return cnn_streamlines(obj.Model, threads=preferences.threads())
    from ..infer.models import model_for_method

    obj.ModelEntry = ""
    entry = model_for_method(domain, obj.Method, "embed one in Model, or train one "
                             "(QuadCNN_TrainModel)")
    if entry is None:
        return None
    obj.ModelEntry = f"{entry.origin}: {entry.path.name}"
    return cnn_streamlines(entry.path, threads=preferences.threads())


def source_of(obj):
    """What a mesh object meshes: the linked object, or (object, face name) when one face
    of it is linked; ValueError when nothing is.  Public: the commands act on a selected
    mesh's source too."""
    link = obj.Source
    if link is None or link[0] is None:
        raise ValueError("no source: link a sketch or a planar face")
    target, subs = link
    subs = [s for s in (subs or []) if s]
    if subs:
        return (target, subs[0])
    return target


def make_quad_mesh(doc, source, name: str = "QuadMesh", **properties):
    """A QuadCNN mesh object for a sketch, a face feature, or (object, 'FaceN')."""
    obj = doc.addObject("Fem::FemMeshObjectPython", name)
    QuadMeshProxy(obj)
    if isinstance(source, (tuple, list)):
        obj.Source = (source[0], [source[1]])
        obj.Part = source[0]
    else:
        obj.Source = (source, [])
        obj.Part = source
    preferred_defaults(obj)
    for key, value in properties.items():
        setattr(obj, key, value)
    obj.StreamlineWires = doc.addObject("Part::Feature", f"{obj.Name}_Streamlines")
    obj.BlockFaces = doc.addObject("Part::Feature", f"{obj.Name}_Blocks")
    if FreeCAD.GuiUp:  # the mesh itself is what the user wants to see; blocks on demand
        from .view_provider import ViewProviderQuadMesh

        ViewProviderQuadMesh(obj.ViewObject)
        obj.BlockFaces.ViewObject.Visibility = False
        obj.StreamlineWires.ViewObject.LineColor = (0.1, 0.62, 0.23)
        obj.StreamlineWires.ViewObject.LineWidth = 3.0
    return obj
