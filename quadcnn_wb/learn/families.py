"""Parametric shape families, one topology each, as the paper trains one network per topology.

Each family draws its parameters uniformly from wide ranges (proportions, notch and hole
positions and sizes) under constraints that keep the topology and the singular structure:
corners stay near right angles, holes keep clear of the boundary and of each other.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..core.input.domain import Domain, domain_from_json


@dataclass(frozen=True)
class Family:
    name: str
    description: str
    ranges: dict  # parameter -> (low, high), drawn uniformly
    build: Callable[[dict], dict]  # parameters -> Domain JSON
    singularities: tuple  # (valence-3 count, valence-5 count) every member has

    @property
    def topology(self) -> str:
        from ..infer.signature import topology_signature

        return topology_signature(self.sample(np.random.default_rng(0))[1])

    def sample(self, rng: np.random.Generator) -> tuple[dict, Domain]:
        params = {k: float(rng.uniform(lo, hi)) for k, (lo, hi) in self.ranges.items()}
        return params, domain_from_json(self.build(params))


def _lines(points) -> list:
    return [{"line": [list(map(float, points[i])), list(map(float, points[(i + 1) %
                                                                          len(points)]))]}
            for i in range(len(points))]


def _circle(cx, cy, r) -> list:
    return [{"circle": {"center": [float(cx), float(cy)], "radius": float(r)}}]


def _semicircle(p) -> dict:
    """A circular segment: chord plus an arc of sweep 150°..210° (corners 75°..105°)."""
    half = math.radians(p["sweep"]) / 2
    a0, a1 = math.pi / 2 - half, math.pi / 2 + half
    start = [math.cos(a0), math.sin(a0)]
    end = [math.cos(a1), math.sin(a1)]
    return {"loops": [[{"line": [end, start]},
                       {"arc": [start, [0.0, 1.0], end]}]]}


def _concave(p) -> dict:
    w, h = p["width"], 1.0
    nw, nd = p["notch_width"] * w, p["notch_depth"] * h
    x0 = p["notch_position"] * (w - nw)
    return {"loops": [_lines([[0, 0], [w, 0], [w, h], [x0 + nw, h], [x0 + nw, h - nd],
                              [x0, h - nd], [x0, h], [0, h]])]}


def _l_shape(p) -> dict:
    w, h = p["width"], 1.0
    tx, ty = p["arm_x"] * w, p["arm_y"] * h
    return {"loops": [_lines([[0, 0], [w, 0], [w, ty], [tx, ty], [tx, h], [0, h]])]}


def _plate_hole(p) -> dict:
    w, h = p["width"], 1.0
    r = p["radius"] * h
    cx = r + p["hole_x"] * (w - 2 * r) * 0.6 + 0.2 * (w - 2 * r)
    cy = r + p["hole_y"] * (h - 2 * r) * 0.6 + 0.2 * (h - 2 * r)
    return {"loops": [_lines([[0, 0], [w, 0], [w, h], [0, h]]), _circle(cx, cy, r)]}


def _four_hole(p) -> dict:
    w, h = p["width"], 1.0
    loops = [_lines([[0, 0], [w, 0], [w, h], [0, h]])]
    for i, j in ((0, 0), (1, 0), (0, 1), (1, 1)):
        r = p[f"r{i}{j}"] * h
        # Hole centres in their own quarter, kept off its edges by the radius plus a gap.
        qx0, qy0 = i * w / 2, j * h / 2
        free_x, free_y = w / 2 - 2 * r - 0.08 * h, h / 2 - 2 * r - 0.08 * h
        cx = qx0 + r + 0.04 * h + p[f"x{i}{j}"] * free_x
        cy = qy0 + r + 0.04 * h + p[f"y{i}{j}"] * free_y
        loops.append(_circle(cx, cy, r))
    return {"loops": loops}


FAMILIES = {
    "semicircle": Family("semicircle", "half disk: a chord and a circular arc",
                         {"sweep": (150.0, 210.0)}, _semicircle, (2, 0)),
    "concave": Family("concave", "rectangle with one rectangular notch in its top side "
                      "(6 convex, 2 concave right-angle corners)",
                      {"width": (1.4, 3.0), "notch_width": (0.15, 0.45),
                       "notch_depth": (0.2, 0.7), "notch_position": (0.1, 0.9)},
                      _concave, (0, 0)),
    "four_hole": Family("four_hole", "rectangular plate with four circular holes, one per "
                        "quarter", {"width": (0.8, 1.25),
                                    **{f"{k}{i}{j}": rng for i in (0, 1) for j in (0, 1)
                                       for k, rng in (("r", (0.08, 0.13)), ("x", (0.25, 0.75)),
                                                      ("y", (0.25, 0.75)))}},
                        _four_hole, (0, 16)),
    "l_shape": Family("l_shape", "L-shaped plate (5 convex, 1 concave right-angle corner)",
                      {"width": (0.6, 2.0), "arm_x": (0.25, 0.75), "arm_y": (0.25, 0.75)},
                      _l_shape, (0, 0)),
    "plate_hole": Family("plate_hole", "rectangular plate with one circular hole",
                         {"width": (1.2, 3.0), "radius": (0.1, 0.35), "hole_x": (0.0, 1.0),
                          "hole_y": (0.0, 1.0)}, _plate_hole, (0, 4)),
}


def family(name: str) -> Family:
    try:
        return FAMILIES[name]
    except KeyError:
        raise ValueError(f"unknown family {name!r} (known: {', '.join(FAMILIES)})") from None
