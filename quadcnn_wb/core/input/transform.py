"""Similarity transforms of Domain JSON (rotation, mirror, uniform scale, shift).

Circles stay circles under these, so the transformed domain is exact; used for data
augmentation and for invariance tests.
"""

from __future__ import annotations

import math

import numpy as np


def similarity(degrees: float = 0.0, scale: float = 1.0, mirror: bool = False) -> np.ndarray:
    a = math.radians(degrees)
    m = scale * np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    return m @ np.diag([-1.0, 1.0]) if mirror else m


def transform_domain_json(data: dict, matrix, shift=(0.0, 0.0)) -> dict:
    """Apply p -> matrix @ p + shift to every point (and radius) of a Domain JSON dict."""
    m = np.asarray(matrix, dtype=float)
    scale = math.sqrt(abs(np.linalg.det(m)))

    def tp(p):
        return (m @ np.asarray(p, dtype=float) + shift).tolist()

    loops = []
    for loop in data["loops"]:
        out = []
        for seg in loop:
            (kind, value), = seg.items()
            if kind == "circle":
                out.append({"circle": {"center": tp(value["center"]),
                                       "radius": value["radius"] * scale}})
            else:
                out.append({kind: [tp(p) for p in value]})
        loops.append(out)
    return {**{k: v for k, v in data.items() if k != "loops"}, "loops": loops}
