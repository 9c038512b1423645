"""Grid lines squared to the boundary in sheared blocks (core/mesh/straighten.py), on the
part that needs it: NIST CTC 01's raised letters (tests/corpus), whose S is a band two
elements thick bent round bends a fifth as long inside as outside."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from quadcnn_wb.core.input.load import load_domain
from quadcnn_wb.core.mesh import quadmesh
from quadcnn_wb.core.mesh.improve import SLIDE_BELOW
from quadcnn_wb.core.mesh.orientation import tiles_exactly
from quadcnn_wb.core.mesh.quadmesh import scaled_jacobians
from quadcnn_wb.core.pipeline import mesh_domain

LETTERS = Path(__file__).parent / "corpus" / "nist_ctc01_letters.brep"


@pytest.fixture(scope="module")
def letters():
    return load_domain(LETTERS)


def test_the_letters_sheared_bands_are_straightened(letters, monkeypatch):
    straight = mesh_domain(letters)
    monkeypatch.setattr(quadmesh, "straightened", lambda nodes, *args: nodes)
    sheared = mesh_domain(letters)
    assert sheared.quality["min_scaled_jacobian"] < SLIDE_BELOW
    assert straight.quality["min_scaled_jacobian"] > 0.7
    # Most of the sheared quads, not only the worst one: the whole band moved together.
    before = scaled_jacobians(sheared.mesh.nodes, sheared.mesh.quads)
    after = scaled_jacobians(straight.mesh.nodes, straight.mesh.quads)
    assert np.mean(after < SLIDE_BELOW) < 0.25 * np.mean(before < SLIDE_BELOW)
    assert straight.structured_share == 1.0
    assert tiles_exactly(straight.mesh.nodes, straight.mesh.quads)


def test_straightened_boundary_nodes_stay_on_the_boundary_in_order(letters):
    result = mesh_domain(letters)
    mesh, domain = result.mesh, result.domain
    on = mesh.boundary
    # Every boundary node lies on one of the part's curves (to round-off of its size).
    curves = [c for loop in domain.loops for c in loop]
    samples = np.concatenate([c.point(np.linspace(0.0, 1.0, 4001)) for c in curves])
    from scipy.spatial import cKDTree

    gap, _ = cKDTree(samples).query(mesh.nodes[on])
    longest = max(c.length for c in curves)
    assert gap.max() < 2e-3 * longest
    # No boundary edge shorter than a tenth of the element size: slid nodes keep clear.
    quads = mesh.quads
    edges = np.concatenate([quads[:, [k, (k + 1) % 4]] for k in range(4)])
    both = on[edges].all(axis=1)
    lengths = np.hypot(*(mesh.nodes[edges[both, 0]] - mesh.nodes[edges[both, 1]]).T)
    assert lengths.min() > 0.1 * result.size
