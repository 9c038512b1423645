"""Singular points that cancel: a valence-3 and a valence-5 point closer than an element
or two are left out of the layout.

Their indices (+1/4 and -1/4) sum to zero, so seen from farther than their distance the
field has no singularity there: such a pair is the harmonic field's answer to a feature
smaller than the mesh (a hole of a few elements, a notch, a fillet between two close
edges), not structure a quad layout needs.  Kept, its eight separatrices leave within an
element of each other, run side by side, and cut faces with three or five corners, or
slivers of no width between the two points (measured on real parts: nist_ctc01 has 40
such pairs within three sizes, perforated_plate over 250, the shape families none).
Left out, the quads there are regular and the layout's only irregular vertices are the
singular points that matter.  Poincaré–Hopf still holds: the sum of the indices left is
the sum of them all.
"""

from __future__ import annotations

import dataclasses

import numpy as np

PAIR = 1.5  # element sizes: a valence-3 and a valence-5 point this close cancel


def without_cancelling_pairs(field, h: float):
    """The field with every cancelling pair's two singular points left out.

    Pairs are taken closest first (a point belongs to one pair at most), so which points
    pair up is decided by distances, which a turned, moved or mirrored copy shares; equal
    distances are decided by the points' distance from the points' centre (also shared)
    and only then by their order."""
    sings = list(field.singularities)
    threes = [i for i, s in enumerate(sings) if s.valence == 3]
    fives = [i for i, s in enumerate(sings) if s.valence == 5]
    if not threes or not fives:
        return field
    xy = np.array([np.asarray(s.xy, dtype=float) for s in sings])
    centre = xy.mean(axis=0)
    candidates = []
    for i in threes:
        for j in fives:
            d = float(np.hypot(*(xy[i] - xy[j])))
            if d < PAIR * h:
                spread = float(np.hypot(*(xy[i] - centre)) + np.hypot(*(xy[j] - centre)))
                candidates.append((round(d / h, 9), round(spread / h, 9), i, j))
    gone: set = set()
    for _, _, i, j in sorted(candidates):
        if i not in gone and j not in gone:
            gone |= {i, j}
    if not gone:
        return field
    kept = tuple(s for k, s in enumerate(sings) if k not in gone)
    return dataclasses.replace(field, singularities=kept)
