"""Design variants of a sketch: its driving dimensions varied within ranges, solved by
FreeCAD's sketcher, kept when they still have the design's topology.

This is what "train a model for this design" learns from: the family of shapes the user
will actually produce by editing this sketch.  The work happens on a copy in a hidden
document, so the user's sketch and undo history are never touched.  No GUI code.
"""

from __future__ import annotations

from dataclasses import dataclass

import FreeCAD
import numpy as np

DIMENSIONAL = ("Distance", "DistanceX", "DistanceY", "Radius", "Diameter", "Angle")


@dataclass(frozen=True)
class Dimension:
    index: int
    name: str  # the constraint's name, or "Constraint<i+1>" like the sketcher shows it
    kind: str
    value: float  # mm, or radians for angles


def dimensions(sketch) -> list[Dimension]:
    """The driving dimensional constraints of a sketch, in constraint order."""
    out = []
    for i, c in enumerate(sketch.Constraints):
        if c.Type in DIMENSIONAL and getattr(c, "Driving", True):
            out.append(Dimension(i, c.Name or f"Constraint{i + 1}", c.Type, float(c.Value)))
    return out


def _domain_json(sketch):
    from .geometry import face_to_domain, source_shape_and_placement

    face, plane, _ = source_shape_and_placement(sketch)
    return face_to_domain(face, plane, sketch.Label)


def make_variants(sketch, count: int, spread: dict, seed: int = 0, report=None):
    """(Domain JSON list, the design's first) of up to `count` variants.

    spread: constraint index -> relative range (0.2 = ±20 %); constraints not named keep
    their value.  A variant the solver cannot satisfy, whose profile breaks, or whose
    topology differs from the design's is skipped; report(done, total) after each try.
    """
    from ..core.input.domain import DomainError
    from ..infer.signature import topology_signature

    rng = np.random.default_rng(seed)
    design = _domain_json(sketch)
    signature = topology_signature(design)
    scratch = FreeCAD.newDocument("QuadCNNVariants", "QuadCNNVariants", True)
    try:
        copy = scratch.copyObject(sketch, False)
        copy.Support = None
        copy.Placement = FreeCAD.Placement()
        scratch.recompute()
        originals = {d.index: d for d in dimensions(copy)}
        out = [design.to_json()]
        tries = 0
        while len(out) < count and tries < 3 * count:
            tries += 1
            for index, fraction in spread.items():
                d = originals[index]
                value = d.value * (1.0 + rng.uniform(-fraction, fraction))
                unit = "rad" if d.kind == "Angle" else "mm"
                copy.setDatum(index, FreeCAD.Units.Quantity(f"{value} {unit}"))
            scratch.recompute()
            try:
                if not copy.isValid():
                    continue
                domain = _domain_json(copy)
            except (DomainError, ValueError, RuntimeError):
                continue
            finally:
                if report is not None:
                    report(len(out), count)
            if topology_signature(domain) == signature:
                out.append(domain.to_json())
        return out, design
    finally:
        FreeCAD.closeDocument(scratch.Name)
