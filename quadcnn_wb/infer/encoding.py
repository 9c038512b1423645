"""How a frame field becomes network input, shared by training and inference.

One point per background node carrying (x, y, v1x, v1y): positions centred on the
bounding box and divided by its diagonal (so any placement and scale give the same
input), then turned by the field's mean direction (the angle of the mean of exp(4i·t),
a quarter of it) so that the crosses are as axis-aligned as they can be — a rotated part
gives (up to quarter turns) the same input, which the network then need not learn.  v1 is
the cross direction in (-45°, 45°] after that turn (v2 is v1 turned by 90°, so it adds
nothing).  The two outputs are the labels of v1 and v2 of the *encoded* frames: where the
turn made the other vector v1, `swapped` says so and the labels trade places.

Optional per-node hints (infer.rays, the "rays" recipe) follow as further columns; they
are the same in any pose, except that some belong to v1 and v2 (rays.PAIRS) and trade
places with them.
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


def encode(nodes: np.ndarray, theta: np.ndarray,
           hints: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(N, 4 + hints) float32 network input, and (N,) bool: v1 and v2 traded places."""
    xy = normalise_positions(nodes)
    theta = canonical_angle(theta)
    turn = float(np.angle(np.mean(np.exp(4j * theta)))) / 4.0
    c, s = np.cos(turn), np.sin(turn)
    xy = xy @ np.array([[c, -s], [s, c]])  # rotates every point by -turn
    turned = theta - turn
    t = canonical_angle(turned)
    swapped = np.abs(((turned - t) + np.pi / 2) % np.pi - np.pi / 2) > np.pi / 4
    settled, quarter = settle(np.column_stack([xy, np.cos(t), np.sin(t)]))
    swapped = swapped ^ quarter
    if hints is not None:
        from .rays import PAIRS

        pairs = [p for p in PAIRS if max(p) < hints.shape[1]]
        settled = np.column_stack([settled, swap_labels(hints, swapped, pairs)])
    return settled.astype(np.float32), swapped


def settle(x: np.ndarray) -> tuple[np.ndarray, bool]:
    """Points in one of the 8 axis-aligned poses, chosen by the shape's moments.

    After the field turn a part can still lie in any quarter turn and either mirror
    image; each multiplies what the network must learn.  The pose with the larger
    second moment along x and non-negative third moments along x and y is unique for
    any shape that is not symmetric (and for a symmetric one the choice does not
    matter).  A quarter turn makes v2 the new v1 (returned True: labels trade places);
    mirrors keep each arm on its axis.
    """
    xy, c, s = x[:, :2], x[:, 2], x[:, 3]
    centred = xy - xy.mean(axis=0)
    quarter = bool((centred[:, 1] ** 2).sum() > (centred[:, 0] ** 2).sum())
    if quarter:  # (x, y) -> (-y, x); (c, s) now describes the turned old v2
        xy = np.column_stack([-xy[:, 1], xy[:, 0]])
        centred = np.column_stack([-centred[:, 1], centred[:, 0]])
    signs = np.where((centred ** 3).sum(axis=0) < 0, -1.0, 1.0)
    xy = xy * signs
    c, s = c * signs[0], s * signs[1]
    flip = c < 0  # the same arm pointing to +x, so t stays in (-45°, 45°]
    c, s = np.where(flip, -c, c), np.where(flip, -s, s)
    return np.column_stack([xy, c, s]), quarter


def swap_labels(labels: np.ndarray, swapped: np.ndarray, pairs=((0, 1),)) -> np.ndarray:
    """Labels between original (v1, v2) order and encoded order (its own inverse).

    The columns of each pair (by default the first two: v1, v2) trade places; the
    others stay.
    """
    out = np.array(labels, copy=True)
    for a, b in pairs:
        out[swapped, a], out[swapped, b] = labels[swapped, b], labels[swapped, a]
    return out


def model_input(mesh, field, width: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """encode() for a background mesh and its field, with the first width - 4 ray hints
    when the model takes more than the paper's 4 columns."""
    hints = None
    if width > 4:
        from .rays import CrossField, field_rays, ray_features

        hints = ray_features(mesh.nodes, mesh.triangles, field.theta, field_rays(field),
                             mesh.element_size, CrossField.on(mesh, field.theta))[:, :width - 4]
    return encode(mesh.nodes, field.theta, hints)
