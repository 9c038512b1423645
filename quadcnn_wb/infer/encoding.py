"""How a frame field becomes network input, shared by training and inference.

One point per background node carrying (x, y, v1x, v1y): positions centred on the
bounding box and divided by its diagonal (so any placement and scale give the same
input), v1 the cross direction in (-45°, 45°] (v2 is v1 turned by 90°, so it adds
nothing).  The two outputs are the labels of v1 and v2.
"""

from __future__ import annotations

import numpy as np

ENCODING = "xy centred on bbox / bbox diagonal; v1 = (cos t, sin t), t in (-pi/4, pi/4]"


def normalise_positions(nodes: np.ndarray) -> np.ndarray:
    lo, hi = nodes.min(axis=0), nodes.max(axis=0)
    return (nodes - 0.5 * (lo + hi)) / float(np.hypot(*(hi - lo)))


def canonical_angle(angle: np.ndarray) -> np.ndarray:
    """The cross direction in (-pi/4, pi/4] for any of its four directions."""
    return -((-np.asarray(angle) + np.pi / 4) % (np.pi / 2) - np.pi / 4)


def encode(nodes: np.ndarray, theta: np.ndarray) -> np.ndarray:
    xy = normalise_positions(nodes)
    t = canonical_angle(theta)
    return np.column_stack([xy, np.cos(t), np.sin(t)]).astype(np.float32)
