"""Streamlines rebuilt from labels (paper §4): with the reference labels as a perfect
prediction they match the traced ones; with useless labels every separatrix falls back to
numerical tracing and the partition is still valid."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from conftest import SHARED_EXAMPLES
from scipy.spatial import cKDTree

from quadcnn_wb.core.field.reference import numerical_reference
from quadcnn_wb.core.input.load import load_domain
from quadcnn_wb.core.layout.partition import build_partition
from quadcnn_wb.infer.reconstruct import reconstruct_streamlines


@functools.cache
def reference(name):
    return numerical_reference(load_domain(SHARED_EXAMPLES / f"{name}.json"))


def hausdorff(a, b):
    return max(cKDTree(b).query(a)[0].max(), cKDTree(a).query(b)[0].max())


@pytest.mark.parametrize("name", ["concave", "l_shape", "plate_hole", "semicircle"])
def test_reference_labels_rebuild_the_reference_partition(name):
    ref = reference(name)
    lines, problems = reconstruct_streamlines(ref.domain, ref.mesh, ref.field, ref.labels)
    assert problems == [] and not any(line.fallback for line in lines)
    assert len(lines) == len(ref.streamlines)
    partition = build_partition(ref.domain, lines, ref.mesh.element_size)
    assert len(partition.blocks) == len(build_partition(ref.domain, ref.streamlines,
                                                        ref.mesh.element_size).blocks)
    h = ref.mesh.element_size
    for line in lines:  # each rebuilt line lies along one traced line
        assert min(hausdorff(line.points, other.points) for other in ref.streamlines) < 1.5 * h
        # and leaves / arrives exactly along a separatrix: smoothing must not bend the
        # ends into a neighbouring separatrix (a sliver block at the singular point)
        for end, p0, p1 in ((line.start, line.points[0], line.points[1]),
                            (line.end, line.points[-1], line.points[-2])):
            if end.kind == "singularity":
                out = (p1 - p0) / np.hypot(*(p1 - p0))
                seps = ref.field.singularities[end.index].directions
                assert np.max(seps @ out) > 1 - 1e-9
        if line.end.kind == "boundary":
            curve = ref.domain.loops[line.end.loop][line.end.segment]
            assert np.array_equal(line.points[-1], curve.point(line.end.param))


def test_useless_labels_fall_back_to_tracing():
    ref = reference("plate_hole")
    lines, problems = reconstruct_streamlines(ref.domain, ref.mesh, ref.field,
                                              np.zeros_like(ref.labels))
    assert len(problems) == sum(s.valence for s in ref.field.singularities)
    assert all(line.fallback for line in lines)
    build_partition(ref.domain, lines, ref.mesh.element_size)  # still four-sided


def test_a_line_across_the_field_is_not_trusted():
    """The verification that catches a walk gone over to a neighbouring band: traced
    streamlines pass it, a line cutting across the crosses does not."""
    from quadcnn_wb.core.layout.streamlines import Endpoint, Streamline
    from quadcnn_wb.infer.rays import CrossField
    from quadcnn_wb.infer.reconstruct import _stray

    ref = reference("four_hole")
    h = ref.mesh.element_size
    field = CrossField(ref.mesh.nodes, ref.mesh.triangles, ref.field.theta)
    for line in ref.streamlines:
        assert _stray(line, field, h) == ""
    long = max(ref.streamlines, key=lambda line: line.length)
    a, b = long.points[0], long.points[-1]
    # the same ends, but a detour that leaves at 45° to the straight run
    normal = np.array([-(b - a)[1], (b - a)[0]])
    mid = 0.5 * (a + b) + 0.5 * normal
    bent = np.vstack([np.linspace(a, mid, 30), np.linspace(mid, b, 30)[1:]])
    detour = Streamline(points=bent, start=Endpoint("boundary"), end=Endpoint("boundary"),
                        capped=False, start_direction=None)
    assert "across the field" in _stray(detour, field, h)


def test_rebuilt_four_hole_partition_from_reference_labels():
    """Dense streamlines a few elements apart (four holes, 16 singular points): perfect
    labels give the reference's own blocks.  Hopping to the best-aligned labelled vector
    alone drifts over to the next band where bands run two elements apart (69 blocks,
    2 of the 20 connections between singular points lost): a candidate off the line
    ahead pays for it (LATERAL)."""
    ref = reference("four_hole")
    lines, problems = reconstruct_streamlines(ref.domain, ref.mesh, ref.field, ref.labels)
    assert not problems
    rebuilt = build_partition(ref.domain, lines, ref.mesh.element_size)
    traced = build_partition(ref.domain, ref.streamlines, ref.mesh.element_size)
    assert len(rebuilt.blocks) == len(traced.blocks)
    connections = sum(line.end.kind == "singularity" for line in lines)
    assert connections == sum(line.end.kind == "singularity" for line in ref.streamlines)
