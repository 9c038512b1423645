"""The user's QuadCNN defaults (Edit → Preferences → QuadCNN), in FreeCAD's parameters.

Read by new mesh objects, the registry (model folder) and the cnn path (threads); written
by the preferences page, whose widgets store straight into these parameters.
"""

from __future__ import annotations

from pathlib import Path

import FreeCAD

PARAMETERS = "User parameter:BaseApp/Preferences/Mod/QuadCNN"
METHODS = ("auto", "cnn", "numerical")


def _group():
    return FreeCAD.ParamGet(PARAMETERS)


def element_size() -> float:
    return max(0.0, _group().GetFloat("ElementSize", 0.0))


def target_nodes() -> int:
    return max(64, _group().GetInt("TargetNodes", 2048))


def method() -> str:
    index = _group().GetInt("Method", 0)
    return METHODS[index] if 0 <= index < len(METHODS) else "auto"


def model_folder() -> str:
    return _group().GetString("ModelFolder", "")


def user_model_folder() -> Path:
    """Where user models go inside FreeCAD: the folder chosen here, else FreeCAD's user
    data folder's QuadCNN/models (registered with infer.user_folder at import of
    quadcnn_wb.freecad; $QUADCNN_MODELS still overrides it)."""
    chosen = model_folder()
    return Path(chosen) if chosen else Path(FreeCAD.getUserAppDataDir()) / "QuadCNN" / "models"


def threads() -> int:
    return max(1, _group().GetInt("Threads", 1))
