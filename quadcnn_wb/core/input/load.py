"""A domain from a file: Domain JSON v1, or the first planar face of a CAD file.

Dispatching on the file type lives here, above both readers: the CAD reader builds its
domain with domain.py's validation, so domain.py cannot also call the CAD reader without
the two importing each other.
"""

from __future__ import annotations

import json
from pathlib import Path

from .cad_import import read_cad_face
from .domain import Domain, DomainError, domain_from_json

CAD_SUFFIXES = {".step", ".stp", ".brep", ".brp", ".iges", ".igs"}


def load_domain(path) -> Domain:
    """Domain from a Domain JSON v1 file or a STEP/BREP/IGES file (first planar face)."""
    path = Path(path)
    if path.suffix.lower() in CAD_SUFFIXES:
        return read_cad_face(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise DomainError(f"{path}: no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise DomainError(f"{path}: cannot read: {exc}") from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise DomainError(f"{path}: not valid JSON ({exc.msg} at line {exc.lineno}, "
                          f"column {exc.colno})") from None
    return domain_from_json(data)
