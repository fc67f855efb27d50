"""The tpee-ompl command line: output, JSON, and one-line errors with non-zero exit codes."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tpee_ompl.cli import main
from tpee_ompl.sectors import posture_preset

START = [*posture_preset(1), 0.0, 0.0]
GOAL = [*posture_preset(4), 0.0, 0.0]


def _args(*extra: str) -> list[str]:
    return ["plan", "--from", "1", "--to", "4", "--start", *map(str, START), "--goal", *map(str, GOAL), *extra]


def test_plan_with_rrtconnect_prints_a_valid_path_as_json(capsys):
    assert main(_args("--planner", "rrtconnect", "--time", "2", "--json")) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["exact"] and out["valid"]
    np.testing.assert_allclose(out["path"][0], START, atol=1e-6)
    np.testing.assert_allclose(out["path"][-1], GOAL, atol=1e-6)
    assert out["collision_checks"] > 0


def test_plan_prints_validity_and_length_in_text(capsys):
    assert main(_args("--planner", "rrtconnect", "--time", "2")) == 0
    out = capsys.readouterr().out
    assert "valid (checkMotion on every segment): True" in out and "length" in out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["plan", "--from", "1", "--to", "9"], "unknown sector 9"),
        (["plan", "--from", "1", "--to", "4", "--planner", "magic"], "invalid choice"),
        (["plan", "--from", "1", "--to", "4", "--start", "nan", "0", "0", "0", "--goal", "0", "1", "0", "0"], "not a finite number"),
        (["plan", "--from", "1", "--to", "4", "--samples", "0"], "positive integer"),
    ],
)
def test_bad_arguments_exit_non_zero_with_one_line(capsys, argv, message):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code != 0
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


def test_start_in_collision_is_one_line_on_stderr(capsys):
    argv = ["plan", "--from", "1", "--to", "4", "--start", "-0.085", "0.299", "-0.799", "-1.202", "--goal", *map(str, GOAL)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "in collision" in err


def test_missing_urdf_is_one_line_on_stderr(capsys, tmp_path):
    assert main(_args("--urdf", str(tmp_path / "missing.urdf"))) == 2
    assert "URDF file not found" in capsys.readouterr().err
