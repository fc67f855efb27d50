"""``tpee-ompl bench`` / ``experiments/run_benchmark.py``: parsing, defaults from one source, clear errors."""

from __future__ import annotations

import argparse
import dataclasses
import sys
import types

import pytest

from tpee_ompl.bench.config import ANYTIME_PLANNERS, CLI_PLANNER_NAMES, CampaignConfig
from tpee_ompl.bench.planners import PLANNER_FACTORIES
from tpee_ompl.cli.bench import build_parser, config_from_args, main, register, run


def test_command_line_defaults_are_the_config_defaults():
    cfg = config_from_args(build_parser().parse_args([]))
    default = CampaignConfig()
    assert dataclasses.replace(cfg, name=default.name) == default
    assert cfg.name == "planning_necessary"  # the results folder is named after the query set


def test_options_reach_the_config():
    args = build_parser().parse_args(["--queries", "some/set.json", "--samples", "10", "20", "--anytime",
                                      "--checkers", "discrete", "--alt-checker-samples", "10", "--workers", "3",
                                      "--seed", "9", "--planners", "RRTstar", "InformedRRTstar"])
    cfg = config_from_args(args)
    assert cfg.name == "set" and cfg.sample_caps == (10, 20) and cfg.anytime_budgets == ()
    assert cfg.checkers == ("discrete",) and cfg.alt_checker_caps == (10,)
    assert cfg.workers == 3 and cfg.seed == 9 and cfg.iteration_planners == ("RRTstar", "InformedRRTstar")


def test_register_adds_the_bench_subcommand_with_an_example(capsys):
    parser = argparse.ArgumentParser(prog="tpee-ompl")
    sub = parser.add_subparsers(dest="command", required=True)
    register(sub, argparse.RawDescriptionHelpFormatter)
    args = parser.parse_args(["bench", "--samples", "30", "--workers", "1"])
    assert args.func is run and args.samples == [30] and args.workers == 1
    with pytest.raises(SystemExit) as exc:
        parser.parse_args(["bench", "--help"])
    assert exc.value.code == 0
    assert "example:" in capsys.readouterr().out


def test_cli_planner_names_are_the_anytime_planners():
    assert tuple(CLI_PLANNER_NAMES.values()) == ANYTIME_PLANNERS
    assert set(CLI_PLANNER_NAMES.values()) <= set(PLANNER_FACTORIES)


def test_missing_dask_gives_a_clear_error_and_exits_1(monkeypatch, capsys, tmp_path):
    """A missing optional extra is a runtime condition (exit 1, as view without meshcat); it exited 2, a usage error's."""
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    code = main(["--dask", "local", "--samples", "10", "--anytime", "--out", str(tmp_path), "--no-progress"])
    err = capsys.readouterr().err
    assert code == 1 and "pip install" in err and "dask" in err
    assert not list(tmp_path.iterdir())  # nothing started


def test_a_malformed_dask_address_is_a_usage_error_naming_dask(capsys, tmp_path):
    pytest.importorskip("distributed")
    code = main(["--dask", "foo", "--samples", "10", "--anytime", "--out", str(tmp_path), "--no-progress"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "error: --dask 'foo': missing port" in err and "tcp://host:port" in err
    assert not list(tmp_path.iterdir())


def test_more_workers_than_cores_are_warned_about(caplog, monkeypatch, tmp_path):
    """Timed runs sharing cores are slower than alone: `--workers 100000` was accepted without a word."""
    import tpee_ompl.bench.executors as executors
    import tpee_ompl.cli.bench as cli_bench

    def stop(*a, **k):
        raise ValueError("stopped before any work (test)")

    monkeypatch.setattr(cli_bench.os, "cpu_count", lambda: 2)
    monkeypatch.setattr(executors, "make_executor", stop)
    with caplog.at_level("WARNING"):
        assert main(["--workers", "3", "--samples", "10", "--anytime", "--out", str(tmp_path), "--no-progress"]) == 2
    assert "--workers 3 on a machine with 2 core(s)" in caplog.text
    caplog.clear()
    with caplog.at_level("WARNING"):
        main(["--workers", "2", "--samples", "10", "--anytime", "--out", str(tmp_path), "--no-progress"])
    assert "cores" not in caplog.text


def test_resume_of_a_folder_without_campaign_is_a_clear_error(capsys, tmp_path):
    assert main(["--resume", str(tmp_path), "--workers", "1", "--no-progress"]) == 2
    assert "campaign.json" in capsys.readouterr().err


def test_resume_of_a_folder_it_may_not_write_in_is_a_usage_error_naming_it(capsys, tmp_path, monkeypatch):
    """It was exit 1 with "PermissionError: ... .lock" (root may write anywhere: the check is simulated)."""
    import tpee_ompl.cli.bench as cli_bench

    monkeypatch.setattr(cli_bench.os, "access", lambda path, mode: False)
    assert main(["--resume", str(tmp_path), "--workers", "1", "--no-progress"]) == 2
    assert capsys.readouterr().err.strip().endswith(f"--resume {tmp_path}: the folder is not writable (the "
                                                    "campaign's logs, lock and database are written there)")


def test_list_problems_prints_every_problem_and_runs_nothing(capsys, tmp_path):
    from tpee_ompl.bench.problems import PROBLEM_NAMES

    assert main(["--list-problems", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].split()[:3] == ["problem", "dim", "queries"]
    listed = {line.split()[0]: line.split()[1:3] for line in out[1:]}
    assert set(listed) == set(PROBLEM_NAMES)
    assert listed["wearer"] == ["4", "120"] and listed["arm6"] == ["6", "10"]
    assert not list(tmp_path.iterdir())


def test_problem_option_takes_the_problem_defaults():
    cfg = config_from_args(build_parser().parse_args(["--problem", "arm6", "--samples", "10"]))
    assert cfg.problem == "arm6" and cfg.name == "arm6" and cfg.queries is None
    assert cfg.checkers == ("discrete",) and "LibraryDimensionRRT" not in cfg.anytime_planners


def test_unknown_problem_is_refused_in_one_line(tmp_path):
    from helpers.cli_run import assert_refused, run_cli

    assert_refused(run_cli(["bench", "--problem", "bad-name", "--out", str(tmp_path)], tmp_path), 2, "--problem",
                   "bad-name")
    assert not list(tmp_path.iterdir())


def test_validator_a_problem_lacks_is_refused_naming_the_option(capsys, tmp_path):
    assert main(["--problem", "arm4", "--checkers", "batched", "--out", str(tmp_path), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert "--checkers" in err and "arm4" in err and len(err.splitlines()) == 1
    assert not list(tmp_path.iterdir())


def test_resume_keeps_the_campaigns_worker_count_unless_workers_is_given(tmp_path, robot, monkeypatch):
    """The default --workers 2 overwrote a --workers 1 campaign's count on every resume, and with it the checker's
    threads: one database then mixed timings taken under two set-ups."""
    from helpers.bench_standins import tiny_config, write_query_file

    import json

    import tpee_ompl.bench.campaign as campaign

    cfg = tiny_config(write_query_file(tmp_path / "q.json", robot, n=1), tmp_path, sample_caps=(30,), anytime_budgets=())
    folder = campaign.run_campaign(cfg, report=False, progress_bar=False).directory
    meta = json.loads((folder / "campaign.json").read_text(encoding="utf-8"))
    meta["config"]["workers"] = 3  # as if run with --workers 3
    (folder / "campaign.json").write_text(json.dumps(meta), encoding="utf-8")
    seen: list = []
    done = types.SimpleNamespace(interrupted=False, failed_tasks=[], skipped_logs=[])
    monkeypatch.setattr(campaign, "resume_campaign", lambda d, executor, workers, **kw: seen.append(workers) or done)
    monkeypatch.setattr("tpee_ompl.cli.bench._print_result", lambda result: None)
    assert main(["--resume", str(folder), "--no-progress"]) == 0
    assert main(["--resume", str(folder), "--workers", "2", "--no-progress"]) == 0
    assert seen == [3, 2]


