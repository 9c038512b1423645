"""The random-plate benchmark: valid members, the same for a seed, and its summary."""

from __future__ import annotations

import json

import numpy as np

from quadcnn_wb.bench.plates import main, random_plate
from quadcnn_wb.core.input.domain import domain_from_json


def test_every_member_is_a_valid_domain_with_holes_and_slots():
    rng = np.random.default_rng(7)
    kinds = set()
    for _ in range(60):
        data = random_plate(rng)
        domain = domain_from_json(data)  # raises DomainError on an invalid member
        assert domain.area > 0
        kinds |= {len(loop) for loop in data["loops"][1:]}
    assert kinds == {1, 4}  # round holes and slots both drawn


def test_the_same_seed_draws_the_same_plates():
    def draw(seed):
        rng = np.random.default_rng(seed)
        return [json.dumps(random_plate(rng)) for _ in range(5)]

    assert draw(3) == draw(3) and draw(3) != draw(4)


def test_the_summary_counts_the_members(capsys, tmp_path):
    assert main(["-n", "2", "--seed", "2", "--save", str(tmp_path)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert len(out) == 3 and out[-1].startswith("default: all in blocks ")
    whole = int(out[-1].split("all in blocks ")[1].split("/")[0])
    assert whole == sum(" share 1.000 " in line for line in out[:2])
    assert len(list(tmp_path.iterdir())) == 2 - whole
