"""The pose a part is meshed in: the same for every turned, mirrored, moved or rescaled
copy of it, so that those copies get the transformed mesh and not merely a similar one.

gmsh's triangulation depends on where the part lies and in which order its curves come;
handing it the part in a pose computed from the geometry alone (centroid at the origin,
unit diameter, a chosen straight edge along +x with the part above it, a chosen mirror
image, loops started at a chosen vertex) makes every copy look identical to gmsh.
Choices are made on keys rounded to KEY_DIGITS, so rounding noise cannot flip them; where
keys tie the part is symmetric, or nearly: the image (rounded samples, sorted) that comes
first is taken, which every copy can tell from the others the same way, however nearly
symmetric the part.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .curves import Arc, Line

KEY_DIGITS = 9  # relative precision of the keys that choose the pose
SAMPLES_PER_CURVE = 16  # boundary samples at fixed parameters (they move with the part)


@dataclass(frozen=True)
class Pose:
    center: np.ndarray  # the region's centroid, in part coordinates
    scale: float  # the part's diameter
    matrix: np.ndarray  # orthogonal 2x2 (det -1 for a mirror): part -> pose directions

    @property
    def mirrored(self) -> bool:
        return float(np.linalg.det(self.matrix)) < 0

    def to_unit(self, p) -> np.ndarray:
        return (np.asarray(p, dtype=float) - self.center) @ self.matrix.T / self.scale

    def from_unit(self, q) -> np.ndarray:
        return np.asarray(q, dtype=float) * self.scale @ self.matrix + self.center


def boundary_samples(domain) -> np.ndarray:
    """Points at fixed curve parameters, both ends included: a turned or mirrored copy of
    the part gives the turned or mirrored set (whatever the direction of its curves)."""
    t = np.linspace(0.0, 1.0, SAMPLES_PER_CURVE + 1)
    points = []
    for loop in domain.loops:
        for curve in loop:
            if isinstance(curve, Arc) and curve.is_full:
                continue  # its start angle is arbitrary; circles enter the diameter exactly
            points.append(curve.point(t))
    return np.concatenate(points) if points else np.zeros((0, 2))


def _hull(points: np.ndarray) -> np.ndarray:
    """The convex hull's vertices (all the points where there is no 2D hull)."""
    from scipy.spatial import ConvexHull, QhullError

    if len(points) < 64:
        return points
    try:
        return points[ConvexHull(points).vertices]
    except QhullError:
        return points


def diameter(domain) -> float:
    """The largest distance across the part (rotation-invariant, unlike the bounding box
    diagonal; the same as it for rectangles)."""
    points = boundary_samples(domain)
    circles = [(c.center, c.radius) for loop in domain.loops for c in loop
               if isinstance(c, Arc) and c.is_full]
    best = 0.0
    if len(points):
        far = _hull(points)  # the farthest pair is a pair of hull vertices
        d = far[:, None, :] - far[None, :, :]
        best = float(np.sqrt((d ** 2).sum(-1).max()))
    for centre, radius in circles:
        best = max(best, 2 * radius)
        if len(points):
            best = max(best, float(np.hypot(*(points - centre).T).max()) + radius)
    for (c1, r1) in circles:
        for (c2, r2) in circles:
            best = max(best, float(np.hypot(*(c1 - c2))) + r1 + r2)
    return best


DEFAULT_SIZE_DIVISOR = 40  # default element size: the part's diameter / this


def default_size(domain) -> float:
    """The part's diameter / 40: the bounding-box diagonal for rectangles, and unlike it
    the same for a turned copy."""
    return diameter(domain) / DEFAULT_SIZE_DIVISOR


def _key(value: float, scale: float) -> float:
    return round(value / scale, KEY_DIGITS)


def area_centroid(domain) -> np.ndarray:
    """Centroid of the region (holes subtracted): curves as fine polygons sampled at fixed
    parameters, full circles exactly.  Unlike the boundary's mean it sees where holes are.
    Summed about a point of the part, not the origin: for a part far away the products
    of absolute coordinates would cancel away most digits."""
    origin = np.asarray(domain.loops[0][0].p0, dtype=float)
    t = np.linspace(0.0, 1.0, SAMPLES_PER_CURVE + 1)[:-1]
    area, moment = 0.0, np.zeros(2)
    for loop in domain.loops:
        if len(loop) == 1 and isinstance(loop[0], Arc) and loop[0].is_full:
            c = loop[0]
            signed = math.pi * c.radius ** 2 * (1.0 if c.sweep > 0 else -1.0)
            area += signed
            moment += signed * (np.asarray(c.center, dtype=float) - origin)
            continue
        poly = np.concatenate([curve.point(t) for curve in loop]) - origin
        x, y = poly[:, 0], poly[:, 1]
        xn, yn = np.roll(x, -1), np.roll(y, -1)
        cross = x * yn - xn * y
        area += 0.5 * cross.sum()
        moment += np.array([((x + xn) * cross).sum(), ((y + yn) * cross).sum()]) / 6.0
    return moment / area + origin


def canonical_pose(domain) -> Pose:
    """The pose of DESIGN's invariance rule; computed once per domain (it is asked for by
    the background mesh, every free-face fill and the stand-in, and costs a scan of the
    boundary), kept in the domain's own __dict__ (a frozen dataclass)."""
    cached = getattr(domain, "__dict__", {}).get("_canonical_pose")
    if cached is None:
        cached = _canonical_pose(domain)
        if hasattr(domain, "__dict__"):
            domain.__dict__["_canonical_pose"] = cached
    return cached


def _canonical_pose(domain) -> Pose:
    points = boundary_samples(domain)
    circles = [c for loop in domain.loops for c in loop if isinstance(c, Arc) and c.is_full]
    center = area_centroid(domain)
    scale = diameter(domain)
    directions, along_edge = _directions(domain, center, scale, points, circles)
    angles = np.linspace(0.0, 2 * math.pi, SAMPLES_PER_CURVE, endpoint=False)
    ring = np.column_stack([np.cos(angles), np.sin(angles)])  # fixed in the turned frame
    # The mirror that keeps what the rotation chose: the chosen edge on +x with the part
    # above it (x -> -x), or the direction to the farthest point along +x (y -> -y).
    flip = np.array([-1.0, 1.0]) if along_edge else np.array([1.0, -1.0])
    axis = 0 if along_edge else 1
    best = None
    for direction in directions:
        angle = -math.atan2(direction[1], direction[0])
        c, s = math.cos(angle), math.sin(angle)
        rotation = np.array([[c, -s], [s, c]])
        turned = np.concatenate([(points - center) @ rotation.T] + [
            (np.asarray(k.center) - center) @ rotation.T + k.radius * ring for k in circles])
        mirror = np.eye(2)
        skew = _key(float((turned[:, axis] ** 3).mean()), scale ** 3)
        if skew < 0 or (skew == 0 and _mirror_image_first(turned / scale, flip)):
            mirror = np.diag(flip)
        image = _image(turned * np.diag(mirror) / scale)
        if best is None or _first(image, best[0]):
            best = image, mirror @ rotation
    return Pose(center=center, scale=scale, matrix=best[1])


MIRROR_DIGITS = 9  # the samples' grid for telling a nearly symmetric part's images apart


def _image(unit_points) -> np.ndarray:
    """The samples rounded to MIRROR_DIGITS, sorted by y then x: what two poses of a part
    are compared by."""
    given = np.round(unit_points, MIRROR_DIGITS) + 0.0
    return given[np.lexsort((given[:, 0], given[:, 1]))]


def _first(a, b) -> bool:
    """Whether image ``a`` comes before image ``b`` (the first sample that differs, by y
    then x)."""
    differ = np.nonzero((a != b).any(axis=1))[0]
    if not len(differ):
        return False
    k = int(differ[0])
    return (a[k, 1], a[k, 0]) < (b[k, 1], b[k, 0])


def _mirror_image_first(unit_points, flip) -> bool:
    """For a part symmetric about the chosen axis to KEY_DIGITS: whether its mirror image
    (``flip``) comes first (_image, _first).  A part symmetric to round-off rounds alike
    both ways (no mirror); one asymmetric by a little more (held-out 0035: 3e-10 of its
    size) was handed to gmsh as itself in one copy and as its mirror image in a mirrored
    copy, whose numbers then rounded differently at gmsh's own grid
    (gmsh_geometry.UNIT_DIGITS): other triangles.  Both copies compare the same two
    images, so both pick the same one."""
    return _first(_image(unit_points * flip), _image(unit_points))


def _directions(domain, center, scale, points, circles) -> tuple:
    """(the directions that may be turned to +x, whether they are straight edges).

    The chosen straight edge (domain on its left): the longest, ties going to the one
    farther from the centroid; edges still tied are all candidates, and the pose whose
    image comes first takes it (_canonical_pose).  A tie once went to the edge whose
    start was farther, which a mirror reverses: a part symmetric but for 1e-5 of its
    size (held-out sensor-assembly f165) had its mirrored copy turned by the other edge
    of the pair, so gmsh got the other image (other triangles, 22 blocks against 17).
    Without straight edges: the directions from the centroid to the farthest samples
    (or to the farthest circle's centre).
    """
    best_key, directions = None, []
    for loop in domain.loops:
        for curve in loop:
            if not isinstance(curve, Line):
                continue
            mid = 0.5 * (curve.p0 + curve.p1)
            key = (_key(curve.length, scale), _key(float(np.hypot(*(mid - center))), scale))
            if best_key is None or key > best_key:
                best_key, directions = key, []
            if key == best_key:
                directions.append(curve.p1 - curve.p0)
    if best_key is not None:
        return directions, True
    if len(points):
        far = np.round(np.hypot(*(points - center).T) / scale, KEY_DIGITS)
        return [points[k] - center for k in np.nonzero(far == far.max())[0]], False
    return [_towards_a_circle(circles, center, scale)], False


def _towards_a_circle(circles, center, scale) -> np.ndarray:
    """For a part of full circles only: towards the centre farthest from the centroid
    (ties: the larger circle, then input order, which a symmetric pattern makes
    immaterial).  Circles about the centroid itself give no direction (one concentric
    with it once made round-off pick the pose); all of them concentric: any direction
    gives gmsh the same circles."""
    best_key, direction = None, np.array([1.0, 0.0])
    for c in circles:
        offset = np.asarray(c.center, dtype=float) - center
        distance = _key(float(np.hypot(*offset)), scale)
        if distance <= 10.0 ** -(KEY_DIGITS - 3):
            continue
        key = (distance, _key(c.radius, scale))
        if best_key is None or key > best_key:
            best_key, direction = key, offset
    return direction
