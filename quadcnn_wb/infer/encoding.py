"""How a frame field becomes network input, shared by training and inference.

One point per background node carrying (x, y, v1x, v1y): positions centred on the
bounding box and divided by its diagonal (so any placement and scale give the same
input), then turned by the field's mean direction (the angle of the mean of exp(4i·t),
a quarter of it) so that the crosses are as axis-aligned as they can be — a rotated part
gives (up to quarter turns) the same input, which the network then need not learn.  v1 is
the cross direction in (-45°, 45°] after that turn (v2 is v1 turned by 90°, so it adds
nothing).  The two outputs are the labels of v1 and v2 of the *encoded* frames: where the
turn made the other vector v1, `swapped` says so and the labels trade places.
"""

from __future__ import annotations

import numpy as np

ENCODING = ("xy centred on bbox / bbox diagonal, turned by -arg(mean exp(4it))/4; "
            "v1 = (cos t, sin t), t in (-pi/4, pi/4] after the turn")


def normalise_positions(nodes: np.ndarray) -> np.ndarray:
    lo, hi = nodes.min(axis=0), nodes.max(axis=0)
    return (nodes - 0.5 * (lo + hi)) / float(np.hypot(*(hi - lo)))


def canonical_angle(angle: np.ndarray) -> np.ndarray:
    """The cross direction in (-pi/4, pi/4] for any of its four directions."""
    return -((-np.asarray(angle) + np.pi / 4) % (np.pi / 2) - np.pi / 4)


def encode(nodes: np.ndarray, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(N, 4) float32 network input, and (N,) bool: v1 and v2 traded places."""
    xy = normalise_positions(nodes)
    theta = canonical_angle(theta)
    turn = float(np.angle(np.mean(np.exp(4j * theta)))) / 4.0
    c, s = np.cos(turn), np.sin(turn)
    xy = xy @ np.array([[c, -s], [s, c]])  # rotates every point by -turn
    turned = theta - turn
    t = canonical_angle(turned)
    swapped = np.abs(((turned - t) + np.pi / 2) % np.pi - np.pi / 2) > np.pi / 4
    return np.column_stack([xy, np.cos(t), np.sin(t)]).astype(np.float32), swapped


def swap_labels(labels: np.ndarray, swapped: np.ndarray) -> np.ndarray:
    """Labels between original (v1, v2) order and encoded order (its own inverse)."""
    out = np.array(labels, copy=True)
    out[swapped] = out[swapped][:, ::-1]
    return out
