"""Make the project's own Python packages visible inside FreeCAD.

FreeCAD runs Debian's /usr/bin/python3; gmsh, onnxruntime and friends are installed in
the checkout's `.venv` (made with --system-site-packages from that same interpreter), so
appending its site-packages is all plain `freecadcmd` needs: no environment variables.
Appended, not prepended, so FreeCAD keeps the system numpy/scipy it was built with.
"""

from __future__ import annotations

import sys
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]


def venv_site_packages() -> Path:
    version = f"python{sys.version_info.major}.{sys.version_info.minor}"
    return REPO_ROOT / ".venv" / "lib" / version / "site-packages"


def add_project_packages() -> bool:
    """Append the venv's site-packages to sys.path once; False when there is no venv."""
    site = venv_site_packages()
    if not site.is_dir():
        return False
    if str(site) not in sys.path:
        sys.path.append(str(site))
    return True


def resource_path(*parts: str) -> str:
    return str(REPO_ROOT.joinpath("resources", *parts))
