"""Random planar shapes for the robustness campaign and the property-based tests.

Star-shaped polygons (3 to 12 corners), some edges bulged into arcs, with up to two holes
(circles or squares), at a scale drawn from 1 µm to 100 km, turned, mirrored and moved.
Most draws are valid domains; some are not (a hole crossing the outer loop, a bulge
crossing a neighbour), which is the point: those must be refused with a clear reason.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.input.transform import similarity, transform_domain_json


def _star_polygon(rng, corners: int) -> np.ndarray:
    gaps = rng.uniform(0.4, 1.0, size=corners)
    angles = np.cumsum(gaps) / gaps.sum() * 2 * math.pi + rng.uniform(0, 2 * math.pi)
    radii = rng.uniform(0.45, 1.0, size=corners)
    return np.column_stack([radii * np.cos(angles), radii * np.sin(angles)])


def _edge(p, q, rng, bulge_chance: float) -> dict:
    if rng.random() >= bulge_chance:
        return {"line": [p.tolist(), q.tolist()]}
    chord = q - p
    normal = np.array([chord[1], -chord[0]])  # right of the edge: outside a CCW loop
    sagitta = rng.uniform(-0.12, 0.25) * np.hypot(*chord)
    mid = 0.5 * (p + q) + sagitta * normal / np.hypot(*normal)
    return {"arc": [p.tolist(), mid.tolist(), q.tolist()]}


def _hole(rng, outer: np.ndarray) -> list:
    centre = outer.mean(axis=0) + rng.uniform(-0.35, 0.35, size=2)
    size = rng.uniform(0.05, 0.22)
    if rng.random() < 0.6:
        return [{"circle": {"center": centre.tolist(), "radius": float(size)}}]
    turn = rng.uniform(0, math.pi / 2)
    square = [centre + size * np.array([math.cos(turn + k * math.pi / 2),
                                        math.sin(turn + k * math.pi / 2)]) for k in range(4)]
    return [{"line": [square[k].tolist(), square[(k + 1) % 4].tolist()]} for k in range(4)]


def random_shape(rng: np.random.Generator) -> tuple[dict, dict]:
    """(Domain JSON v1, how it was drawn) for one random shape."""
    corners = int(rng.integers(3, 13))
    outer = _star_polygon(rng, corners)
    bulge_chance = 0.3 if rng.random() < 0.5 else 0.0
    loops = [[_edge(outer[k], outer[(k + 1) % corners], rng, bulge_chance)
              for k in range(corners)]]
    holes = int(rng.choice([0, 0, 1, 2]))
    for _ in range(holes):
        loops.append(_hole(rng, outer))
    scale = 10.0 ** rng.uniform(-6, 5)
    degrees = rng.uniform(0, 360)
    mirror = bool(rng.integers(2))
    shift = rng.uniform(-1, 1, size=2) * scale * 10
    data = transform_domain_json({"units": "mm", "loops": loops},
                                 similarity(degrees, scale=scale, mirror=mirror), shift)
    return data, {"corners": corners, "holes": holes, "arcs": bulge_chance > 0,
                  "scale": scale, "degrees": degrees, "mirror": mirror}
