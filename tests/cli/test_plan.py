"""``tpee-ompl plan|aim|track``: output, JSON, and one-line errors with non-zero exit codes."""

from __future__ import annotations

import functools
import json
from pathlib import Path

import numpy as np
import pytest
from helpers.cli_queries import GOAL, START, start_goal_args

from tpee_ompl.cli.main import main


def _args(*extra: str) -> list[str]:
    return ["plan", "--from", "1", "--to", "4", *start_goal_args(), *extra]


def test_plan_with_rrtconnect_prints_a_valid_path_as_json(capsys):
    assert main(_args("--planner", "rrtconnect", "--time", "2", "--json")) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["exact"] and out["valid"]
    np.testing.assert_allclose(out["path"][0], START, atol=1e-6)
    np.testing.assert_allclose(out["path"][-1], GOAL, atol=1e-6)
    assert out["collision_checks"] > 0


def test_a_path_printed_with_four_decimals_can_be_planned_again(capsys):
    assert main(_args("--planner", "dimension-rrt", "--samples", "300")) == 0
    rows = [line.split() for line in capsys.readouterr().out.splitlines() if line.startswith("  ")]
    start, goal = rows[0], rows[-1]  # DOF1/DOF2 5e-5 rad off the postures: taken as them
    assert main(["plan", "--from", "1", "--to", "4", "--start", *start, "--goal", *goal, "--planner", "dimension-rrt",
                 "--samples", "300", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["exact"] and np.allclose(out["path"][0][:2], START[:2], atol=1e-6)


def test_a_goal_off_its_sectors_posture_is_a_usage_error_naming_it(capsys):
    # the goal of sector 4 given as sector 1's posture: before, a 2-waypoint motion labelled "1 -> 4"
    argv = ["plan", "--from", "1", "--to", "4", "--start", *map(str, START), "--goal", *map(str, START)]
    assert main(argv + ["--planner", "rrtconnect"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "--goal" in err and "sector 4's posture" in err


def test_plan_prints_validity_and_length_in_text(capsys):
    assert main(_args("--planner", "rrtconnect", "--time", "2")) == 0
    out = capsys.readouterr().out
    assert "valid (checkMotion on every segment): True" in out and "length" in out


def test_start_in_collision_is_one_line_on_stderr(capsys):
    argv = ["plan", "--from", "1", "--to", "4", "--start", "-0.085", "0.299", "-0.799", "-1.202",
            "--goal", *map(str, GOAL)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "in collision" in err


def test_aim_prints_a_collision_free_aim_with_clear_line_of_sight(capsys):
    assert main(["aim", "--target", "5", "2", "1.5", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["collision_free"] and out["line_of_sight_clear"] and out["aim_error_m"] < 1e-9


def test_aim_with_another_urdf_aims_with_that_model(capsys, tmp_path):
    """``aim --urdf`` used to solve the packaged model's IK: 0.03 m off with a 3 cm longer pan-tilt offset."""
    from tpee_ompl.resources import model_file

    urdf, srdf = model_file("wearer_arm.urdf"), model_file("wearer_arm.srdf")
    text = Path(urdf).read_text(encoding="utf-8")
    old = '<origin xyz="0 0.1 0"/><axis xyz="0 -1 0"/>'
    assert text.count(old) == 1
    (tmp_path / "longer.urdf").write_text(text.replace(old, '<origin xyz="0 0.13 0"/><axis xyz="0 -1 0"/>'),
                                          encoding="utf-8")
    assert main(["aim", "--target", "5", "2", "1.5", "--json"]) == 0
    packaged = json.loads(capsys.readouterr().out)
    assert main(["aim", "--target", "5", "2", "1.5", "--urdf", str(tmp_path / "longer.urdf"), "--srdf", str(srdf),
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["aim_error_m"] < 1e-9 and out["q_rad"] != packaged["q_rad"]


def test_aim_at_a_target_inside_the_body_is_one_line(capsys):
    assert main(["aim", "--target", "0", "0", "1.2"]) == 2
    assert "inside" in capsys.readouterr().err


def test_track_jitter_on_a_boundary_causes_no_cross_sector_motion(capsys):
    assert main(["track", "--script", "jitter", "--duration", "5", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["events"]["cross-sector"] <= 1 and out["events"]["aim"] > 0


def test_track_with_the_library_seeds_both_of_its_fallback_planners_with_seed(capsys, monkeypatch):
    from tpee_ompl.cli import plan as plan_cli
    from tpee_ompl.library import tracker

    seeds = {}
    real_drrt, real_default = plan_cli.dimension_rrt_planner, tracker.make_default_planner

    @functools.wraps(real_drrt)  # the parser reads its flags' defaults from the signature
    def drrt(robot, **kw):
        seeds["dimension_rrt"] = kw.get("seed")
        return real_drrt(robot, **kw)

    def default(robot, **kw):
        seeds["same_sector"] = kw.get("seed")
        return real_default(robot, **kw)

    monkeypatch.setattr(plan_cli, "dimension_rrt_planner", drrt)
    monkeypatch.setattr(tracker, "make_default_planner", default)
    assert main(["track", "--planner", "library", "--script", "jump", "--duration", "2", "--seed", "7", "--json"]) == 0
    assert seeds == {"dimension_rrt": 7, "same_sector": 7}


def test_plan_reports_its_samples_and_says_when_the_time_limit_came_before_the_sample_cap(capsys):
    assert main(_args("--planner", "rrtstar", "--samples", "10000000", "--time", "0.3")) == 0
    out = capsys.readouterr().out
    assert "stopped by --time 0.3 before --samples 10000000" in out
    assert main(_args("--planner", "dimension-rrt", "--samples", "300", "--json")) == 0
    assert json.loads(capsys.readouterr().out)["samples"] == 300


def test_track_output_writes_the_sector_as_an_integer_and_times_exactly(tmp_path, capsys, monkeypatch):
    import tpee_ompl.library.tracker as tracker_module

    results = []
    real_run = tracker_module.Tracker.run
    monkeypatch.setattr(tracker_module.Tracker, "run", lambda self, stream: results.append(real_run(self, stream))
                        or results[-1])
    out = tmp_path / "traj.csv"
    assert main(["track", "--script", "jump", "--duration", "2", "--rate", "2", "--planner", "dimension-rrt",
                 "-o", str(out)]) == 0
    lines = out.read_text(encoding="utf-8").splitlines()
    assert lines[0] == "t,dof1,dof2,dof3,dof4,sector"
    rows = [line.split(",") for line in lines[1:]]
    assert rows and all(r[5] in {"0", "1", "2", "3", "4"} for r in rows)  # was 3.000000000000000000e+00 (0: in a motion)
    written = np.array([[float(v) for v in r[:5]] for r in rows])
    np.testing.assert_array_equal(written, np.c_[results[0].times, results[0].configurations])  # to the last bit


def test_queries_given_a_folder_or_a_pipe_says_what_it_is(capsys, tmp_path):
    """Both used to be "not found"."""
    import os

    fifo = tmp_path / "q.json"
    os.mkfifo(fifo)
    for given, said in ((tmp_path, "is a folder, not a query file"), (fifo, "is not a regular file")):
        assert main(["plan", "--from", "1", "--to", "4", "--queries", str(given)]) == 2
        err = capsys.readouterr().err.strip()
        assert err.startswith("tpee-ompl plan: error: --queries: ") and said in err and "\n" not in err


@pytest.mark.parametrize("quiet", [False, True])
def test_a_track_that_lasts_more_than_two_seconds_shows_its_progress_unless_no_progress(capsys, monkeypatch, quiet):
    """A long --duration x --rate ran a minute without a word; a short one stays silent (the bar waits 2 s)."""
    import time

    from tpee_ompl.library.tracker import Tracker

    real = Tracker.step

    def slow(self, *a):
        time.sleep(0.12)
        return real(self, *a)

    monkeypatch.setattr(Tracker, "step", slow)
    argv = ["track", "--script", "jitter", "--duration", "3", "--rate", "10", "--json"] + (["--no-progress"] if quiet else [])
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert ("track" in err and "30/30" in err) != quiet


def test_a_short_track_prints_nothing_on_stderr(capsys):
    assert main(["track", "--script", "jitter", "--duration", "2", "--json"]) == 0
    assert capsys.readouterr().err == ""


def test_track_json_says_where_its_csv_went(capsys, tmp_path):
    csv = tmp_path / "traj.csv"
    assert main(["track", "--script", "jitter", "--duration", "1", "--json", "-o", str(csv)]) == 0
    assert json.loads(capsys.readouterr().out)["output"] == str(csv) and csv.is_file()


@pytest.mark.parametrize("planner", ["rrtstar", "rrtconnect", "bitstar"])
@pytest.mark.parametrize("stall", ["5", "1000"])
def test_stall_with_a_planner_that_does_not_read_it_is_a_usage_error(capsys, planner: str, stall: str):
    """--stall was ignored without a word by the planners that do not use it (plan --planner rrtstar --stall 5)."""
    assert main(_args("--planner", planner, "--stall", stall, "--time", "0.05")) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"tpee-ompl plan: error: --stall is read by --planner dimension-rrt and library, not {planner}"


@pytest.mark.parametrize("planner", [[], ["--planner", "dimension-rrt"], ["--planner", "library"]])
def test_stall_is_taken_by_the_planners_that_read_it(capsys, planner: list[str]):
    assert main(_args(*planner, "--stall", "5", "--time", "0.5", "--json")) == 0
    assert json.loads(capsys.readouterr().out)["exact"]
