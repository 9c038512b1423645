"""A temporary picture of the frame field in the 3D view, like the paper's Figures 1 and 12
(GUI only): a cross at every background node, the singular points by valence, and — when
a model fits the shape — the frame vectors the network labels 1 drawn thick in red.

Nothing is added to the document; the overlay lives in the view's scene graph until the
command runs again (which removes it) or the document closes.
"""

from __future__ import annotations

import numpy as np

from .view_provider import VALENCE_COLOURS, marker_set, overall_binding

_OVERLAYS = {}  # view id -> the overlay's SoSeparator
CROSS_COLOUR = (0.35, 0.35, 0.35)
LABEL_COLOUR = (0.85, 0.05, 0.05)


def field_segments(nodes, theta, arm: float):
    """(2M, 2) segment end points: both arms of the cross at every node."""
    out = []
    for turn in (0.0, np.pi / 2):
        d = arm * np.column_stack([np.cos(theta + turn), np.sin(theta + turn)])
        out.extend([nodes - d, nodes + d])
    starts = np.concatenate([out[0], out[2]])
    ends = np.concatenate([out[1], out[3]])
    return np.stack([starts, ends], axis=1).reshape(-1, 2)


def labelled_segments(nodes, theta, labels, arm: float):
    """Segments of the label-1 vectors only (v1 for column 0, v2 for column 1)."""
    pieces = []
    for col, turn in ((0, 0.0), (1, np.pi / 2)):
        on = labels[:, col] == 1
        d = arm * np.column_stack([np.cos(theta[on] + turn), np.sin(theta[on] + turn)])
        pieces.append(np.stack([nodes[on] - d, nodes[on] + d], axis=1).reshape(-1, 2))
    return np.concatenate(pieces) if pieces else np.zeros((0, 2))


def compute(domain, nodes: int = 2048):
    """(reference, labels or None, model entry or None) for the shape."""
    from ..core.field.reference import numerical_reference
    from ..infer.models import model_for
    from ..infer.predictor import Predictor

    ref = numerical_reference(domain, nodes=nodes)
    entry = model_for(domain)
    labels = None
    if entry is not None:
        labels = Predictor(entry.path).field_labels(ref.mesh, ref.field)
    return ref, labels, entry


def _lines(coin, points3d, colour, width):
    sep = coin.SoSeparator()
    light = coin.SoLightModel()
    light.model = coin.SoLightModel.BASE_COLOR
    sep.addChild(light)
    style = coin.SoDrawStyle()
    style.lineWidth = width
    material = coin.SoBaseColor()
    material.rgb = colour
    coords = coin.SoCoordinate3()
    coords.point.setValues(0, len(points3d), points3d)
    lines = coin.SoLineSet()
    lines.numVertices.setValues(0, len(points3d) // 2, [2] * (len(points3d) // 2))
    for node in (style, overall_binding(coin), material, coords, lines):
        sep.addChild(node)
    return sep


def build_overlay(ref, labels, placement):
    """The Coin scene of the field in the source's plane (global coordinates)."""
    from pivy import coin

    from .geometry import to_global

    def lift(xy):
        return [tuple(v) for v in to_global(placement, np.asarray(xy).tolist())]

    arm = 0.3 * ref.mesh.element_size
    root = coin.SoAnnotation()  # over the shape and any mesh, like the paper's figures
    theta = ref.field.theta
    root.addChild(_lines(coin, lift(field_segments(ref.mesh.nodes, theta, arm)),
                         CROSS_COLOUR, 1.0))
    if labels is not None:
        root.addChild(_lines(coin, lift(labelled_segments(ref.mesh.nodes, theta, labels,
                                                          1.4 * arm)), LABEL_COLOUR, 3.0))
    for valence, colour in VALENCE_COLOURS.items():
        chosen = [s.xy for s in ref.field.singularities if s.valence == valence]
        if chosen:
            root.addChild(marker_set(coin, lift(chosen), colour))
    return root


def toggle(view, domain, placement, nodes: int = 2048) -> str:
    """Show the field overlay in `view`, or remove it when shown; returns a summary."""
    key = id(view)
    graph = view.getSceneGraph()
    if key in _OVERLAYS:
        graph.removeChild(_OVERLAYS.pop(key))
        return "frame field hidden"
    ref, labels, entry = compute(domain, nodes)
    overlay = build_overlay(ref, labels, placement)
    graph.addChild(overlay)
    _OVERLAYS[key] = overlay
    counts = ref.field.valences()
    model = (f"; {int(labels.sum())} label-1 vectors from {entry.path.name}" if entry
             else "; no model for this topology")
    return (f"frame field: {ref.mesh.n_nodes} nodes, {counts[3]} valence-3 and {counts[5]} "
            f"valence-5 singular points{model}")
