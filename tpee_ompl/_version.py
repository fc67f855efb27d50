"""The package's version (one home: ``tpee_ompl.__version__``, the wheel's metadata and the benchmark logs read it)."""

from __future__ import annotations

import functools
from pathlib import Path

__version__ = "0.1.0"


@functools.lru_cache(maxsize=1)
def code_version() -> str:
    """What a result was made with: ``__version__``, plus ``+g<commit>`` (``.dirty`` with uncommitted changes to
    tracked files, ``.unknown`` when git could not tell) when the package runs from a git checkout that tracks it;
    ``__version__`` alone from a wheel."""
    import subprocess  # here, not at import: ``import tpee_ompl`` (the console script's first step) stays short

    here = Path(__file__).resolve().parent

    def git(*args: str) -> str | None:
        try:  # no optional locks: a status taking index.lock could make a commit running meanwhile fail
            out = subprocess.run(["git", "--no-optional-locks", "-C", str(here), *args], capture_output=True,
                                 text=True, timeout=10)
        except (OSError, subprocess.SubprocessError):
            return None
        return out.stdout.strip() if out.returncode == 0 else None

    # the package's own files must be tracked: a wheel installed in a venv inside some repository is not that commit
    if git("ls-files", "--error-unmatch", "_version.py") is None:
        return __version__
    sha = git("rev-parse", "--short=12", "HEAD")
    if not sha:
        return __version__
    status = git("status", "--porcelain", "--untracked-files=no")
    return f"{__version__}+g{sha}{'.unknown' if status is None else '.dirty' if status else ''}"
