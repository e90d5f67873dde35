"""Fixtures of the Python module's tests. Run from the repository root:

    PYTHONPATH=build/python ZCHECK_EXE=build/cli/zcheck /usr/bin/python3 -m pytest -q tests/python
"""
import pytest

import zcheck
from helpers import W, H


@pytest.fixture(scope="session")
def default_scene():
    return zcheck.Scene.from_file("builtin:default")


@pytest.fixture(scope="session")
def default_checker(default_scene):
    return zcheck.Checker(default_scene)


@pytest.fixture(scope="session")
def small_camera(default_scene):
    """The default scene's own camera at 160x120."""
    return default_scene.default_camera.replace(width=W, height=H)


@pytest.fixture
def small_camera_file(tmp_path, small_camera):
    path = tmp_path / "camera.json"
    path.write_text(small_camera.to_json())
    return str(path)
