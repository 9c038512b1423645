"""Lines across blocks whose maps fold (layout.cuts.fold_cuts, rounds.FoldCutter).

A band bent round small arcs (the raised letter S of NIST CTC 01's "LST",
tests/corpus/nist_ctc01_letters) has no singular point inside to cut it: one block runs
round both bends, its sides' nodes spread evenly along each, and the map folds where
the inner side is short.  Freed, the band got unstructured quads (34 % of the face in
blocks); a field line across the fold splits the band's sides, and the face is all
blocks with no irregular vertex but the field's own."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from quadcnn_wb.core import rounds
from quadcnn_wb.core.field.reference import background_and_field
from quadcnn_wb.core.input.load import load_domain
from quadcnn_wb.core.layout.cuts import fold_cuts
from quadcnn_wb.core.mesh.orientation import tiles_exactly
from quadcnn_wb.core.pipeline import mesh_domain

CORPUS = Path(__file__).parent / "corpus"
LETTERS = CORPUS / "nist_ctc01_letters.brep"


def test_the_letters_are_in_the_corpus():
    names = [entry["name"] for entry in json.loads((CORPUS / "manifest.json").read_text())]
    assert "nist_ctc01_letters" in names
    assert "nist_ctc01_letters.brep" in (CORPUS / "SOURCES.md").read_text()


@pytest.fixture(scope="module")
def letters():
    return mesh_domain(load_domain(LETTERS))


def test_lines_across_the_folds_make_the_bent_band_blocks(letters):
    assert letters.structured_share == 1.0, letters.problem
    assert letters.quality["min_scaled_jacobian"] > 0.4
    assert tiles_exactly(letters.mesh.nodes, letters.mesh.quads)
    # One loop: no connecting cut; every cut is a line across a fold, boundary to boundary.
    assert letters.cuts
    assert all(c.start.kind == "boundary" and c.end.kind == "boundary" for c in letters.cuts)
    # They add no irregular vertex: the field's singular points (and the corners the
    # quality measure reads) are all there is.
    own = len(letters.reference.field.singularities) + letters.feature_corners
    assert letters.quality["irregular_vertices"] <= own + 1


def test_without_them_the_band_is_freed(monkeypatch):
    monkeypatch.setattr(rounds, "FOLD_CUT_ROUNDS", 0)
    result = mesh_domain(load_domain(LETTERS))
    assert result.structured_share < 0.5
    assert "degenerate" in result.problem


def test_a_fold_gets_one_line_and_a_short_one_none():
    domain = load_domain(LETTERS)
    background, field = background_and_field(domain, 2048, {})
    # The middle of the S (where its lower bend's map folded in the pipeline's frame is
    # immaterial here: any place inside the band).
    place = np.array([-55.0, -25.0])
    cuts = fold_cuts(domain, background, field, [place, place + 0.1], [])
    assert len(cuts) == 1  # the second starts within two elements of the first
    line = cuts[0]
    assert line.start.kind == line.end.kind == "boundary"
    assert np.hypot(*np.diff(line.points, axis=0).T).sum() >= background.element_size
    # Existing lines near the start block it too.
    assert fold_cuts(domain, background, field, [place], cuts) == []


def test_a_worse_mesh_with_the_lines_loses_to_the_one_without(monkeypatch):
    # Held-out 0016 at diameter/100 (now corpus blend_pocket_kink): its thin wall's
    # blocks fold; lines across them gave all blocks with a worst element of 0.29, the
    # rebuild that frees them 0.88.  The lines' mesh is kept only if it is the better.
    from quadcnn_wb.core.input.pose import diameter

    domain = load_domain(CORPUS / "blend_pocket_kink.brep")
    size = diameter(domain) / 100
    best = mesh_domain(domain, size=size)
    monkeypatch.setattr(rounds, "GOOD_JACOBIAN", -1.0)  # the lines' mesh, unraced
    raw = mesh_domain(domain, size=size)
    assert best.structured_share == 1.0
    assert best.quality["min_scaled_jacobian"] > raw.quality["min_scaled_jacobian"] + 0.2
