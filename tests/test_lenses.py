"""A short lens (two lines between the same corner and singular point) is one line."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from test_corpus import CORPUS, PARTS

from quadcnn_wb.core.input.load import load_domain
from quadcnn_wb.core.layout.lenses import LENS_LENGTH, without_short_lenses
from quadcnn_wb.core.layout.streamlines import Endpoint, Streamline

H = 1.0
TIP = np.array([0.0, 0.0])
POINT = np.array([-1.1, 0.0])  # a valence-3 point 1.1 elements from a 270° corner's tip
CORNER = Endpoint("corner", 7, 0, 3, 0.5)
SINGULAR = Endpoint("singularity", 2, branch=0)


def _from_tip(direction, length=0.25):
    """The corner's line: a quarter step along its direction, then onto the point."""
    d = np.array([math.cos(math.radians(direction)), math.sin(math.radians(direction))])
    return np.array([TIP, TIP + length * d, POINT])


def _lens(scale=1.0):
    up = Streamline(_from_tip(135.0) * scale, CORNER, SINGULAR)
    down = Streamline(_from_tip(225.0) * scale, dataclasses.replace(CORNER, branch=1),
                      dataclasses.replace(SINGULAR, branch=1))
    return up, down


@pytest.mark.parametrize("point_to_tip", [False, True])
def test_the_two_lines_become_their_mean_from_the_tip_along_the_bisector(point_to_tip):
    up, down = _lens()
    if point_to_tip:  # the upper line is the point's own, traced to the tip
        up = Streamline(up.points[::-1], up.end, up.start)
    far = Streamline(np.array([[5.0, 5.0], [6.0, 6.0]]), Endpoint("singularity", 4, branch=0),
                     Endpoint("boundary", -1, 0, 1, 0.3))
    # a line from above that ended a third of the way along the lower one
    onto = Streamline(np.array([[-0.2, 2.0], [-0.2, 1.0], down.points[1]]),
                      Endpoint("singularity", 5, branch=2), Endpoint("streamline", 1, param=0.3))
    out = without_short_lenses([far, up, down, onto], H)
    assert len(out) == 3
    mean = out[1]
    assert mean.start.kind == "corner" and mean.end.kind == "singularity"
    assert np.array_equal(mean.points[0], TIP) and np.array_equal(mean.points[-1], POINT)
    heading = mean.points[1] - mean.points[0]
    assert abs(math.degrees(math.atan2(heading[1], heading[0]))) == pytest.approx(180.0)
    assert np.allclose(mean.points[:, 1], 0.0, atol=1e-12)  # midway: on the bisector
    # the line that ended on the dropped one ends on the mean, renumbered, its end on it
    moved = out[2]
    assert moved.end.kind == "streamline" and moved.end.index == 1
    assert abs(moved.points[-1][1]) < 1e-12 and 0.0 < moved.end.param < 1.0
    assert np.array_equal(moved.points[0], onto.points[0])
    assert out[0] is far


def test_long_lines_between_the_same_points_stay_two():
    up, down = _lens(scale=1.01 * LENS_LENGTH / 1.1)
    assert len(without_short_lenses([up, down], H)) == 2


def test_two_singular_points_joined_both_ways_keep_both_lines():
    # Each line leaves its own point along a separatrix of its own: the face between
    # them has the points' corners (a hole stored as a polygon of 90 sides).
    up, down = _lens()
    there = Streamline(up.points, Endpoint("singularity", 1, branch=1), SINGULAR)
    back = Streamline(down.points[::-1], SINGULAR, Endpoint("singularity", 1, branch=0))
    assert len(without_short_lenses([there, back], H)) == 2


def test_the_first_layout_of_a_part_with_such_lenses_is_all_blocks(monkeypatch):
    # nist_ctc01_plate at its default size: three valence-3 points an element from a
    # notch's or a slot's corner caught both its lines; the lenses were faces of two
    # corners, and the part paid for the layout on a background four times as fine.
    from quadcnn_wb.core import pipeline

    domain = load_domain(CORPUS / PARTS["nist_ctc01_plate"]["file"])
    calls = []
    real = pipeline._mesh_on_background

    def counted(domain, size, nodes, *args, **kw):
        calls.append(nodes)
        return real(domain, size, nodes, *args, **kw)

    monkeypatch.setattr(pipeline, "_mesh_on_background", counted)
    result = pipeline.mesh_domain(domain)
    assert calls == [2048]
    assert result.structured_share == 1.0
    assert result.quality["min_scaled_jacobian"] > 0.5
