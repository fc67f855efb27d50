"""The experiment scripts the README's figures come from start from a clean clone: ``--help`` works and says what
the script measures (run as the README does, ``PYTHONPATH=. python experiments/X.py``)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPTS = sorted(p.name for p in (ROOT / "experiments").glob("*.py") if p.name != "_common.py")


def _run(script: str, *args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    return subprocess.run([sys.executable, f"experiments/{script}", *args], cwd=ROOT, env=env, capture_output=True,
                          text=True, timeout=300)


@pytest.mark.slow
@pytest.mark.parametrize("script", SCRIPTS)
def test_every_experiment_script_answers_help_with_its_whole_first_paragraph(script):
    """``mesh_robots.py --help`` ran the whole experiment, and seven descriptions stopped mid-sentence (the
    docstring's first line only)."""
    done = _run(script, "--help")
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.startswith("usage: ")
    description = " ".join(done.stdout.split("\n\n")[1].split())
    assert description.endswith((".", ":", ")", "?")) and not description.startswith("options:"), description


@pytest.mark.slow
def test_the_single_motion_script_runs_with_the_validator_it_swaps_in():
    """It replaced ``BatchedMotionValidator.all_valid`` with a function of the old signature and crashed on every
    run once ``checkMotion`` passed its probes (the README's 18.4 / 29.5 ms came from it)."""
    done = _run("single_motion_checks.py", "--queries", "1", "--reps", "1", "--limit", "1")
    assert done.returncode == 0, done.stderr[-2000:]
    assert "bisection / all at once:" in done.stdout


@pytest.mark.slow
def test_the_convergence_script_repeats_one_run_and_sets_the_pipeline_beside_aorrtc():
    """Issue 17's in-process comparison and the same run repeated (the samples a run reaches depend on the
    machine's speed at the time): both modes run, and ``--repeat`` without exactly one ``--only`` query is refused."""
    refused = _run("pipeline_convergence.py", "--repeat", "2")
    assert refused.returncode == 2 and "--repeat" in refused.stderr.splitlines()[-1]
    done = _run("pipeline_convergence.py", "--only", "1", "--repeat", "2", "--budgets", "0.01")
    assert done.returncode == 0, done.stderr[-2000:]
    assert "query 1 at 0.01 s, seed 1, 2 times: samples" in done.stdout
    done = _run("pipeline_convergence.py", "--aorrtc", "--only", "1", "--budgets", "0.01")
    assert done.returncode == 0, done.stderr[-2000:]
    assert "AORRTC 1 s: median cost" in done.stdout and "pipeline 0.01 s: median cost" in done.stdout
