"""Every way a domain can be wrong gets a DomainError naming the problem and its place."""

from __future__ import annotations

import pytest
from conftest import circle, rect

from quadcnn_wb.core.input.domain import DomainError, domain_from_json
from quadcnn_wb.core.input.load import load_domain

L = lambda a, b: {"line": [a, b]}  # noqa: E731

BAD_DOMAINS = {
    "not an object": ([rect(1, 1)], r"must be an object"),
    "no loops": ({"units": "mm"}, r"non-empty 'loops' list"),
    "empty loop": ({"loops": [[]]}, r"loop 0: must be a non-empty list"),
    "unknown kind": ({"loops": [[{"spline": [[0, 0], [1, 1]]}]]},
                     r"loop 0, segment 0: unknown segment kind 'spline'"),
    "two keys": ({"loops": [[{"line": [[0, 0], [1, 0]], "arc": []}]]},
                 r"loop 0, segment 0: a segment is an object with one key"),
    "text coordinate": ({"loops": [[L(["a", 0], [1, 0]), L([1, 0], [0, 1]),
                                    L([0, 1], ["a", 0])]]},
                        r"loop 0, segment 0: start must be a pair of numbers"),
    "bool coordinate": ({"loops": [[L([0, 0], [1, 0]), L([1, 0], [True, 1]),
                                    L([True, 1], [0, 0])]]},
                        r"loop 0, segment 1: end must be a pair of numbers"),
    "three coordinates": ({"loops": [[L([0, 0, 0], [1, 0])]]},
                          r"loop 0, segment 0: start must be a pair of numbers"),
    "open loop": ({"loops": [[L([0, 0], [1, 0]), L([1, 0], [1, 1]), L([1, 1], [0, 0.5])]]},
                  r"loop 0: open loop, segment 2 ends at \(0, 0.5\) but segment 0 starts"),
    "open hole": ({"loops": [rect(4, 4), [L([1, 1], [2, 1]), L([2, 1], [2, 2])]]},
                  r"loop 1: open loop"),
    "collinear arc": ({"loops": [[L([0, 0], [2, 0]), {"arc": [[2, 0], [1, 1e-14], [0, 0]]}]]},
                      r"loop 0, segment 1: arc points are collinear"),
    "arc ends coincide": ({"loops": [rect(4, 4), [{"arc": [[1, 1], [2, 2], [1, 1]]}]]},
                          r"loop 1, segment 0: arc start and end coincide"),
    "zero radius": ({"loops": [rect(4, 4), circle(1, 1, 0)]},
                    r"loop 1, segment 0: circle radius must be positive"),
    "negative radius": ({"loops": [rect(4, 4), circle(1, 1, -0.5)]},
                        r"loop 1, segment 0: circle radius must be positive"),
    "text radius": ({"loops": [rect(4, 4), [{"circle": {"center": [1, 1], "radius": "2"}}]]},
                    r"loop 1, segment 0: circle radius must be a finite number"),
    "circle with others": ({"loops": [[{"circle": {"center": [0, 0], "radius": 1}},
                                       L([1, 0], [2, 0])]]},
                           r"loop 0, segment 0: a circle must be a loop by itself"),
    "bow tie": ({"loops": [[L([0, 0], [1, 1]), L([1, 1], [1, 0]), L([1, 0], [0, 1]),
                            L([0, 1], [0, 0])]]},
                r"loop 0 intersects itself: segments 0 and 2 cross at \(0.5, 0.5\)"),
    "arc crossing a line": ({"loops": [[L([0, 0], [2, 0]), L([2, 0], [2, 1]),
                                        {"arc": [[2, 1], [1, -0.5], [0, 1]]}, L([0, 1], [0, 0])]]},
                            r"loop 0 intersects itself: segments 0 and 2 cross"),
    "doubling back": ({"loops": [[L([0, 0], [2, 0]), L([2, 0], [1, 0]), L([1, 0], [1, 1]),
                                  L([1, 1], [0, 0])]]},
                      r"loop 0 intersects itself: segments 0 and 1 overlap"),
    "hole crosses outer": ({"loops": [rect(2, 1), circle(2, 0.5, 0.3)]},
                           r"loops 0 and 1 intersect: loop 0 segment 1 and loop 1 segment 0"),
    "hole touches outer": ({"loops": [rect(2, 1), circle(1, 0.5, 0.5)]},
                           r"loops 0 and 1 touch: .* meet at .*: the face pinches to no "
                           r"width there"),
    # Two holes of a real part that meet at one point (a slot cut up to a keyhole's rim:
    # fsr-dance-pad's breadboard platform, face 103).
    "holes touch": ({"loops": [rect(4, 4), circle(1, 1, 0.5), circle(2, 1, 0.5)]},
                    r"loops 1 and 2 touch: loop 1 segment 0 and loop 2 segment 0 meet at "
                    r"\(1.5, 1\): the face pinches"),
    "hole corner on a hole": ({"loops": [rect(4, 4), circle(1, 1, 0.5),
                                         [L([1.5, 1], [2.5, 0.5]), L([2.5, 0.5], [2.5, 1.5]),
                                          L([2.5, 1.5], [1.5, 1])]]},
                              r"loops 1 and 2 touch"),
    "holes overlap": ({"loops": [rect(4, 4), circle(1, 1, 0.5), circle(1.5, 1, 0.5)]},
                      r"loops 1 and 2 intersect"),
    "same hole twice": ({"loops": [rect(4, 4), circle(1, 1, 0.5), circle(1, 1, 0.5)]},
                        r"loops 1 and 2 intersect: .* overlap"),
    "hole outside": ({"loops": [rect(2, 1), circle(5, 5, 0.5)]},
                     r"loop 1 \(a hole\) lies outside the outer loop 0"),
    "outer given second": ({"loops": [circle(1, 0.5, 0.2), rect(2, 1)]},
                           r"loop 1 \(a hole\) lies outside the outer loop 0"),
    "hole in hole": ({"loops": [rect(4, 4), circle(2, 2, 1), circle(2, 2, 0.3)]},
                     r"loop 2 \(a hole\) lies inside hole loop 1"),
    "flat loop": ({"loops": [[L([0, 0], [1, 0]), L([1, 0], [2, 0]), L([2, 0], [0, 0])]]},
                  r"loop 0: zero area"),
    "single point": ({"loops": [[L([1, 1], [1, 1])]]}, r"zero area"),
}


@pytest.mark.parametrize("case", BAD_DOMAINS)
def test_bad_domain_is_refused_with_its_place(case):
    data, message = BAD_DOMAINS[case]
    with pytest.raises(DomainError, match=message):
        domain_from_json(data)


@pytest.mark.parametrize("text, message", [
    ('{"loops": [[{"line": [[0, 0], [1, NaN]]}]]}', r"non-finite coordinate"),
    ('{"loops": [[{"line": [[0, 0], [1e999, 0]]}]]}', r"non-finite coordinate"),
    ('{"loops": [[{"line": [[0, 0], [1, 0]]}', r"not valid JSON .* line 1"),
    ("", r"not valid JSON"),
    ("[1, 2]", r"must be an object"),
])
def test_bad_files_are_refused(write_json, text, message):
    with pytest.raises(DomainError, match=message):
        load_domain(write_json(text))


def test_unreadable_files_are_refused(tmp_path):
    with pytest.raises(DomainError, match="no such file"):
        load_domain(tmp_path / "missing.json")
    with pytest.raises(DomainError, match="cannot read"):
        load_domain(tmp_path)  # a folder
    binary = tmp_path / "binary.json"
    binary.write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(DomainError, match="cannot read"):
        load_domain(binary)
