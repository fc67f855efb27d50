"""The optional interactive viewer (meshcat)."""

from __future__ import annotations

import sys

import pytest

from tpee_ompl.model.sectors import posture_preset
from tpee_ompl.viz import ViewerUnavailableError, view_meshcat


def test_view_meshcat_without_meshcat_says_how_to_install(robot, monkeypatch):
    monkeypatch.setitem(sys.modules, "meshcat", None)  # makes `import meshcat` raise ImportError
    with pytest.raises(ImportError, match="pip install meshcat") as info:
        view_meshcat(robot)
    assert isinstance(info.value, ViewerUnavailableError)


def test_view_meshcat_when_installed(robot, aimed):
    pytest.importorskip("meshcat", reason="optional viewer extra not installed")
    viz = view_meshcat(robot, aimed[0])
    viz.display(posture_preset(1).tolist() + [0.0, 0.0])
