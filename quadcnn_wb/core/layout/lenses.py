"""Two short lines between one corner and one singular point are one line, midway
between them.

A singular point an element or so from a corner catches both of the corner's lines
(held-out 0082: a valence-3 point 1.1 elements from a V-notch's tip read as a 270°
corner; nist_ctc01 three times): they leave the tip 90° apart, arrive along two of the
point's separatrices (or one of them is the point's own line to the tip), and close a
lens, a face of two corners that no block can be.  On a background twice as fine the
point sits two elements off and the corner's lines end on its separatrices instead, a
proper block; on this one the lens left the first layout with free faces and the part
paid for the finer one.  On a true 270° vertex (not a fillet read as one) the corner is
left with two quads where its angle asks three: one irregular vertex for the point's.

The point's index (+1/4) and the corner's missing quarter (a 270° corner asks three
quads and a flat boundary two) cancel, as a valence-3 and a valence-5 point an element
apart do (field.pairs): seen from farther off there is no structure there.  So the two
lines become their mean: it leaves the tip along the corner's bisector (two sectors of
135°, CORNER_TURN each: no corner either side) and goes on through the point opposite
its third separatrix (two sectors of 180°), and the quads round it are regular.  Lines
that ended on either of the two end on the mean line, where their ends are nearest to it.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .crossings import resampled
from .field_rules import bent_to, nearest_on_polyline
from .tracing import SNAP_BLEND

LENS_LENGTH = 2.0  # element sizes: both lines of a lens at most this long
LENS_SAMPLES = 9  # points of the mean line


def without_short_lenses(lines, h: float) -> tuple:
    """``lines`` with each short lens (two lines, each at most LENS_LENGTH long, between
    one corner and one singular point, either way) replaced by its mean line.  Not two
    singular points joined both ways: those lines leave the points along separatrices of
    their own, and the face between them has the points' own corners (a hole stored as a
    polygon of 90 sides has such a pair)."""
    lines = list(lines)
    by_ends: dict = {}
    for k, line in enumerate(lines):
        pair = _corner_and_point(line)
        if pair is not None:
            by_ends.setdefault(pair, []).append(k)
    merged = {}  # dropped line -> kept line
    for group in by_ends.values():
        if len(group) != 2 or any(lines[k].length > LENS_LENGTH * h for k in group):
            continue
        # The mean runs from the corner; one leaving it is kept (if both do, their mean
        # is the same whichever is kept).
        keep, drop = sorted(group, key=lambda k: (lines[k].start.kind != "corner", k))
        lines[keep] = _mean_of(lines[keep], lines[drop])
        merged[drop] = keep
    if not merged:
        return tuple(lines)
    return _renumbered(lines, merged, h)


def _corner_and_point(line):
    ends = {line.start.kind: line.start.index, line.end.kind: line.end.index}
    if set(ends) == {"corner", "singularity"}:
        return ends["corner"], ends["singularity"]
    return None


def _mean_of(keep, other):
    """The mean of two lines from the corner to the point (``keep`` leaves the corner)."""
    a = resampled(np.asarray(keep.points, dtype=float), LENS_SAMPLES)
    b = np.asarray(other.points, dtype=float)
    b = resampled(b if other.start.kind == "corner" else b[::-1], LENS_SAMPLES)
    mean = 0.5 * (a + b)
    mean[0], mean[-1] = keep.points[0], keep.points[-1]
    return dataclasses.replace(keep, points=mean)


def _renumbered(lines, merged: dict, h: float) -> tuple:
    """Drop the merged lines; every T-junction on a merged or mean line moves onto the
    mean line (its end bent there), and line numbers close up."""
    kept = [k for k in range(len(lines)) if k not in merged]
    new_index = {k: i for i, k in enumerate(kept)}
    means = set(merged.values())
    out = []
    for k in kept:
        line = lines[k]
        end = line.end
        if end.kind == "streamline":
            target = merged.get(end.index, end.index)
            if target in means and 0.0 < end.param < 1.0:  # (0 or 1: on the mean's end)
                place, param = nearest_on_polyline(np.asarray(lines[target].points),
                                                   line.points[-1])
                line = dataclasses.replace(line,
                                           points=bent_to(line.points, place, SNAP_BLEND * h))
                end = dataclasses.replace(end, param=param)
            line = dataclasses.replace(line, end=dataclasses.replace(end, index=new_index[target]))
        out.append(line)
    return tuple(out)
