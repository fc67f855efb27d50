"""``tpee_ompl._version``: what a benchmark's results record as the code that made them."""

from __future__ import annotations

import importlib.util
import shutil
import subprocess
from pathlib import Path

import pytest

import tpee_ompl._version as version


def _tracked() -> bool:
    here = Path(version.__file__).resolve().parent
    return subprocess.run(["git", "-C", str(here), "ls-files", "--error-unmatch", "_version.py"],
                          capture_output=True).returncode == 0


@pytest.mark.skipif(not _tracked(), reason="the package does not run from a git checkout here")
def test_from_a_checkout_the_code_version_names_the_commit():
    """Every database said 0.1.0, before and after behaviour changes: nothing told which code made it."""
    head = subprocess.run(["git", "-C", str(Path(version.__file__).parent), "rev-parse", "--short=12", "HEAD"],
                          capture_output=True, text=True).stdout.strip()
    assert version.code_version().startswith(f"{version.__version__}+g{head}")


def test_outside_a_checkout_that_tracks_it_the_code_version_is_the_package_version(tmp_path):
    copy = tmp_path / "_version.py"
    shutil.copy(version.__file__, copy)
    spec = importlib.util.spec_from_file_location("copied_version", copy)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.code_version() == version.__version__
