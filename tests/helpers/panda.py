"""The Panda for tests: skipped with a clear reason when the optional 'robots' extra is missing."""

from __future__ import annotations

import importlib.util

import pytest

needs_panda = pytest.mark.skipif(importlib.util.find_spec("example_robot_data") is None,
                                 reason="example_robot_data missing: install the optional 'robots' extra")
