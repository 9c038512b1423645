"""The user model folder: $QUADCNN_MODELS first, then the host application's (FreeCAD
registers its preferences' folder), else $XDG_DATA_HOME/QuadCNN/models."""

from __future__ import annotations

from pathlib import Path

import pytest

from quadcnn_wb.infer import user_folder
from quadcnn_wb.infer.user_folder import set_host_folder, user_model_folder


@pytest.fixture
def no_host(monkeypatch):
    monkeypatch.setattr(user_folder, "_host_folder", None)
    monkeypatch.delenv("QUADCNN_MODELS", raising=False)


def test_outside_a_host_the_xdg_data_folder(no_host, monkeypatch, tmp_path):
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path))
    assert user_model_folder() == tmp_path / "QuadCNN" / "models"
    monkeypatch.delenv("XDG_DATA_HOME")
    assert user_model_folder() == Path.home() / ".local" / "share" / "QuadCNN" / "models"


def test_a_host_folder_is_asked_each_time_and_the_variable_overrides_it(no_host, monkeypatch,
                                                                        tmp_path):
    chosen = [tmp_path / "first"]
    set_host_folder(lambda: chosen[0])
    assert user_model_folder() == tmp_path / "first"
    chosen[0] = tmp_path / "second"  # the preference changed
    assert user_model_folder() == tmp_path / "second"
    monkeypatch.setenv("QUADCNN_MODELS", str(tmp_path / "override"))
    assert user_model_folder() == tmp_path / "override"
