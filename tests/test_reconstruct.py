"""Streamlines rebuilt from labels (paper §4): with the reference labels as a perfect
prediction they match the traced ones; with useless labels every separatrix falls back to
numerical tracing and the partition is still valid."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from conftest import SHARED_EXAMPLES
from scipy.spatial import cKDTree

from quadcnn_wb.core.domain import load_domain
from quadcnn_wb.core.partition import build_partition
from quadcnn_wb.core.reference import numerical_reference
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
