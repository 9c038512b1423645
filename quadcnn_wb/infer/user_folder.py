"""Where the user's own models (trained for a design) are saved and looked for.

`$QUADCNN_MODELS` overrides everything.  Otherwise a host application that keeps its
own setting says where (FreeCAD registers its preferences' folder, else its user data
folder, when quadcnn_wb.freecad is imported); without one `$XDG_DATA_HOME/QuadCNN/models`
(~/.local/share/QuadCNN/models).  The host registers itself so that infer never imports
it: infer also runs in the command line tools and benchmarks, where there is no FreeCAD.
Only the standard library here, so registering costs FreeCAD's start-up nothing.
"""

from __future__ import annotations

import os
from pathlib import Path

_host_folder = None  # set_host_folder's callable, or None: no host application


def set_host_folder(folder_of) -> None:
    """Make ``folder_of()`` the user model folder unless $QUADCNN_MODELS is set (None:
    no host).  Called each time the folder is asked for: the setting may change."""
    global _host_folder
    _host_folder = folder_of


def user_model_folder() -> Path:
    override = os.environ.get("QUADCNN_MODELS")
    if override:
        return Path(override)
    if _host_folder is not None:
        return Path(_host_folder())
    base = os.environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share"
    return Path(base) / "QuadCNN" / "models"
