"""Round-off must not decide topology: random members of every family, turned by odd
angles, moved by 1e4 of their size, mirrored and rescaled, get the same blocks, quads and
irregular vertices, fully block-structured (a gmsh stand-in counts as a failure); and the
same input gives the same mesh in another process."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from quadcnn_wb.core.input.domain import domain_from_json
from quadcnn_wb.core.input.transform import similarity, transform_domain_json
from quadcnn_wb.core.pipeline import mesh_domain
from quadcnn_wb.learn.families import FAMILIES, family

POSES = {  # (degrees, mirror, scale, shift in part sizes)
    "turned 37°": (37.0, False, 1.0, 0.0),
    "moved 1e4": (0.0, False, 1.0, 1e4),
    "mirrored, turned 211°": (211.0, True, 1.0, 0.0),
    "turned 131°, scale 1e-3": (131.0, False, 1e-3, 3.0),
    "turned 73°, scale 1e3": (73.0, False, 1e3, -7.0),
}
MEMBERS = 2  # per family, drawn with a fixed seed


def signature(result) -> tuple:
    q = result.quality
    return result.structured_share, q["blocks"], q["quads"], q["irregular_vertices"]


def member(name: str, k: int) -> dict:
    rng = np.random.default_rng(2026)
    fam = family(name)
    for _ in range(k + 1):
        params, _ = fam.sample(rng)
    return fam.build(params)


# Known failures, kept visible: they must not start passing unnoticed.
KNOWN: dict = {}
CASES = [pytest.param(name, k, marks=pytest.mark.xfail(strict=True, reason=KNOWN[name, k]))
         if (name, k) in KNOWN else (name, k)
         for name in sorted(FAMILIES) for k in range(MEMBERS)]


@pytest.mark.parametrize("name, k", CASES)
def test_every_pose_of_a_member_gets_the_same_blocks(name, k):
    data = member(name, k)
    base = mesh_domain(domain_from_json(data))
    assert base.structured, base.problem
    size = base.domain.size
    for pose, (degrees, mirror, scale, shift) in POSES.items():
        moved = transform_domain_json(data, similarity(degrees, scale, mirror),
                                      np.full(2, shift * size * scale))
        result = mesh_domain(domain_from_json(moved))
        assert signature(result) == signature(base), pose


def test_a_mirror_image_is_refused_the_same_collapses():
    """A collapsed strip joins places, not whichever vertex of a run of no-segment arcs
    the walk along its side met first: a mirror image walks every block the other way,
    and this member's got conflict rows on other arcs and 51 blocks against 52."""
    params, _ = family("four_hole").sample(np.random.default_rng([2027, 21]))
    data = family("four_hole").build(params)
    base = mesh_domain(domain_from_json(data))
    mirrored = transform_domain_json(data, similarity(211.0, 1.0, True), np.zeros(2))
    assert signature(mesh_domain(domain_from_json(mirrored))) == signature(base)


def test_same_input_same_mesh_in_another_process(tmp_path):
    data = member("four_hole", 0)
    path = tmp_path / "part.json"
    path.write_text(json.dumps(data))
    outputs = []
    for k in range(2):
        out = tmp_path / f"mesh{k}.json"
        run = subprocess.run([sys.executable, "-m", "quadcnn_wb", "mesh", path, "--method",
                              "numerical", "-o", out],
                             capture_output=True, text=True, timeout=300)
        assert run.returncode == 0, run.stderr
        outputs.append(json.loads(out.read_text()))
    here = mesh_domain(domain_from_json(data))
    for key in ("nodes", "quads", "block_of_quad"):
        assert outputs[0][key] == outputs[1][key], key
    assert np.array_equal(np.array(outputs[0]["quads"]), here.mesh.quads)
    assert np.allclose(np.array(outputs[0]["nodes"]), here.mesh.nodes, rtol=0, atol=0)


def test_a_part_with_free_faces_gets_the_same_mesh_under_any_hash_seed(tmp_path):
    """The rounds that give up blocks and dissolve lines keep sets of blocks and lines; no
    set's iteration order (which PYTHONHASHSEED changes from process to process) may decide
    the mesh.  blend_sawtooth at its default size goes through those rounds and keeps
    free faces (a freeing rule tried once made blend_scallop_slots' share 0.566 or 0.569
    by the seed; that part is all blocks since lines across folds, and
    nist_ctc01_logo_bracket, here before, since its logo's narrow bays got square ends)."""
    part = Path(__file__).parent / "corpus" / "blend_sawtooth.brep"
    outputs = []
    for seed in ("1", "2"):
        out = tmp_path / f"mesh{seed}.json"
        env = dict(os.environ, PYTHONHASHSEED=seed)
        run = subprocess.run([sys.executable, "-m", "quadcnn_wb", "mesh", str(part), "--method",
                              "numerical", "-o", str(out)],
                             capture_output=True, text=True, timeout=300, env=env)
        assert run.returncode == 0, run.stderr
        outputs.append(json.loads(out.read_text()))
    assert min(o["block_of_quad"].count(-1) for o in outputs) > 0  # free faces are there
    for key in ("nodes", "quads", "block_of_quad"):
        assert outputs[0][key] == outputs[1][key], key
