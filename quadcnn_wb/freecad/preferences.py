"""The user's QuadCNN defaults (Edit → Preferences → QuadCNN), in FreeCAD's parameters.

Read by new mesh objects, the registry (model folder) and the cnn path (threads); written
by the preferences page, whose widgets store straight into these parameters.
"""

from __future__ import annotations

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


def threads() -> int:
    return max(1, _group().GetInt("Threads", 1))
