"""Topology signature of a domain: what a model trained on one shape family can handle.

Per loop, the corners in cyclic order as quarter turns (1 convex right angle, 3 concave,
and so on; smooth joins are not corners), written from the rotation and direction that
give the smallest string, so rotated, mirrored or re-indexed copies match; holes sorted.
Examples: the concave family is "1:11111133" (one loop), four_hole "5:1111|O|O|O|O".
"""

from __future__ import annotations

from ..core.input.corners import interior_angle, is_corner, nearest_quarters


def loop_corners(loop) -> list[int]:
    if len(loop) == 1 and loop[0].kind == "circle":
        return []
    out = []
    for k, curve in enumerate(loop):
        angle = interior_angle(loop[k - 1], curve)
        if is_corner(angle):
            out.append(nearest_quarters(angle))
    return out


def _canonical(corners: list[int]) -> str:
    if not corners:
        return "O"
    variants = []
    for seq in (corners, corners[::-1]):
        for r in range(len(seq)):
            variants.append("".join(str(c) for c in seq[r:] + seq[:r]))
    return min(variants)


def topology_signature(domain) -> str:
    outer = _canonical(loop_corners(domain.loops[0]))
    holes = sorted(_canonical(loop_corners(loop)) for loop in domain.loops[1:])
    return f"{len(domain.loops)}:" + "|".join([outer] + holes)
