"""``tpee-ompl bench`` refuses every bad input before anything is created: a table of hostile and careless inputs.

Each case runs the real command line as a subprocess and checks: exit 2 (usage) or 1 (runtime: a damaged
query file, as in ``plan``), one line
on stderr naming the option or file, no traceback, no file or folder left behind, existing files unchanged.
Refusals happen before any planning, so each case takes well under a second or two.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.bench_standins import write_query_file
from helpers.cli_run import assert_refused, run_cli, snapshot

pytestmark = pytest.mark.slow  # ~12 s of subprocesses; CI and `make test` run it

ROOT = Path(__file__).resolve().parents[2]
TESTS = ROOT / "tests"
SCRIPT = ROOT / "experiments" / "run_benchmark.py"


@pytest.fixture(scope="module")
def inputs(tmp_path_factory, robot) -> Path:
    """A folder with a good query set, broken ones, a plain file and a folder that is not a campaign."""
    d = tmp_path_factory.mktemp("inputs")
    good = write_query_file(d / "good.json", robot, n=2)
    doc = json.loads(good.read_text())
    (d / "truncated.json").write_text(good.read_text()[:150])
    (d / "version.json").write_text(json.dumps({**doc, "format_version": 99}))
    (d / "other_model.json").write_text(json.dumps({**doc, "model_hash": "0123456789abcdef"}))
    (d / "not_a_set.json").write_text(json.dumps([1, 2, 3]))
    (d / "string_start.json").write_text(json.dumps({**doc, "queries": [{**doc["queries"][0], "start": "abc"}]}))
    q0 = doc["queries"][0]
    (d / "outside_limits.json").write_text(json.dumps({**doc, "queries": [{**q0, "start": q0["start"][:3] + [10.0]}]}))
    (d / "swapped.json").write_text(json.dumps({**doc, "queries": [{**q0, "start": q0["goal"], "goal": q0["start"]}]}))
    (d / "plain.txt").write_text("an existing file\n")
    (d / "not_a_campaign").mkdir()
    (d / "not_a_campaign" / "notes.txt").write_text("hello\n")
    (d / "bad_campaign").mkdir()
    (d / "bad_campaign" / "campaign.json").write_text('{"config": ')
    for name, part, folder in (("logs_a_file", "logs", False), ("lock_a_folder", ".lock", True)):
        (d / name).mkdir()
        (d / name / "campaign.json").write_text("{}")
        (d / name / part).mkdir() if folder else (d / name / part).write_text("x")
    (d / "list_campaign").mkdir()
    (d / "list_campaign" / "campaign.json").write_text("[]")
    meta = {"config": {"queries": None, "seed": 1}, "query_set": "good", "expected_experiments": 1,
            "query_data": [{"start": [0.0] * 4, "goal": [0.0] * 4}]}  # no id
    (d / "bad_query_data").mkdir()
    (d / "bad_query_data" / "campaign.json").write_text(json.dumps(meta))
    (d / "config_list").mkdir()
    (d / "config_list" / "campaign.json").write_text(json.dumps({**meta, "config": [1, 2]}))
    (d / "no_seed").mkdir()
    (d / "no_seed" / "campaign.json").write_text(json.dumps({**meta, "config": {"queries": None}}))
    return d


def _tree(folder: Path) -> list[str]:
    """Every path (files and folders) under ``folder``."""
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


# (id, arguments, expected exit status, words the one-line message must contain).  {in} is the inputs
# folder, {out} the (watched) results parent; every case has a good query set unless it replaces it.
CASES = [
    ("max-queries-negative", ["--max-queries", "-3"], 2, ["--max-queries"]),
    ("max-queries-zero", ["--max-queries", "0"], 2, ["--max-queries"]),
    ("max-queries-text", ["--max-queries", "ten"], 2, ["--max-queries"]),
    ("max-time-nan", ["--max-time", "nan"], 2, ["--max-time"]),
    ("max-time-inf", ["--max-time", "inf"], 2, ["--max-time"]),
    ("max-time-negative", ["--max-time", "-1"], 2, ["--max-time"]),
    ("seed-negative", ["--seed", "-5"], 2, ["--seed"]),
    ("seed-zero", ["--seed", "0"], 2, ["--seed"]),
    ("seed-20-digits", ["--seed", "12345678901234567890"], 2, ["--seed"]),
    ("seed-plus-queries-overflows", ["--seed", "4294967295"], 2, ["--seed", "4294967295"]),
    ("planner-unknown", ["--planners", "Nope"], 2, ["--planners", "Nope"]),
    ("anytime-planner-unknown", ["--anytime", "0.1", "--anytime-planners", "Nope"], 2, ["--anytime-planners", "Nope"]),
    ("planner-twice", ["--planners", "RRTstar", "RRTstar"], 2, ["--planners", "twice"]),
    ("planner-module-missing", ["--planners", "no_such_module_xyz:make"], 2, ["--planners", "no_such_module_xyz"]),
    ("planner-function-missing", ["--planners", "helpers.bench_standins:no_such_factory"], 2, ["--planners", "no_such_factory"]),
    ("queries-missing", ["--queries", "{in}/missing.json"], 2, ["--queries", "missing.json"]),
    ("queries-truncated", ["--queries", "{in}/truncated.json"], 1, ["--queries", "truncated.json", "not a JSON query set"]),
    ("queries-format-version", ["--queries", "{in}/version.json"], 1, ["--queries", "format_version"]),
    ("queries-other-model", ["--queries", "{in}/other_model.json"], 1, ["--queries", "model_hash"]),
    ("queries-not-a-set", ["--queries", "{in}/not_a_set.json"], 1, ["--queries", "JSON object"]),
    ("queries-string-start", ["--queries", "{in}/string_start.json"], 1, ["--queries", "field 'start'"]),
    ("queries-start-outside-limits", ["--queries", "{in}/outside_limits.json"], 1,
     ["--queries", "outside_limits.json", "joint limits"]),
    ("queries-start-and-goal-swapped", ["--queries", "{in}/swapped.json"], 1, ["--queries", "swapped.json", "Table-1 preset"]),
    ("max-time-beyond-a-day", ["--max-time", "1e300"], 2, ["--max-time", "86400"]),
    ("anytime-beyond-a-day", ["--anytime", "1e10"], 2, ["--anytime", "86400"]),
    ("queries-a-folder", ["--queries", "{in}/not_a_campaign"], 2, ["--queries", "not_a_campaign"]),
    ("queries-unknown-name", ["--queries", "no_such_set"], 2, ["--queries", "no_such_set"]),
    ("out-is-a-file", ["--out", "{in}/plain.txt"], 2, ["--out", "plain.txt"]),
    ("out-under-a-file", ["--out", "{in}/plain.txt/sub"], 2, ["--out", "plain.txt"]),
    ("resume-not-a-campaign", ["--resume", "{in}/not_a_campaign"], 2, ["--resume", "not_a_campaign"]),
    ("resume-missing-folder", ["--resume", "{in}/nowhere"], 2, ["--resume", "nowhere"]),
    ("resume-corrupt-campaign", ["--resume", "{in}/bad_campaign"], 2, ["--resume", "bad_campaign"]),
    ("resume-list-campaign", ["--resume", "{in}/list_campaign"], 2, ["--resume", "list_campaign"]),
    ("workers-zero", ["--workers", "0"], 2, ["--workers"]),
    ("workers-negative", ["--workers", "-1"], 2, ["--workers"]),
    ("runs-zero", ["--runs", "0"], 2, ["--runs"]),
    ("samples-zero", ["--samples", "0"], 2, ["--samples"]),
    ("samples-negative", ["--samples", "-5"], 2, ["--samples"]),
    ("samples-nan", ["--samples", "nan"], 2, ["--samples"]),
    ("anytime-negative", ["--anytime", "-1"], 2, ["--anytime"]),
    ("anytime-zero", ["--anytime", "0"], 2, ["--anytime"]),
    ("anytime-nan", ["--anytime", "nan"], 2, ["--anytime"]),
    ("nothing-to-run", ["--samples", "--anytime"], 2, ["--samples", "--anytime"]),
    ("checker-unknown", ["--checkers", "psychic"], 2, ["--checkers"]),
    ("alt-checker-queries-negative", ["--alt-checker-queries", "-1"], 2, ["--alt-checker-queries"]),
    ("alt-checker-samples-zero", ["--alt-checker-samples", "0"], 2, ["--alt-checker-samples"]),
    ("anytime-queries-negative", ["--anytime-queries", "-2"], 2, ["--anytime-queries"]),
    ("dask-workers-zero", ["--dask-workers", "0"], 2, ["--dask-workers"]),
    ("dask-workers-without-dask", ["--dask-workers", "3"], 2, ["--dask-workers", "give --dask"]),
    ("retries-without-dask", ["--retries", "1"], 2, ["--retries", "give --dask"]),
    ("scheduler-malformed-is-named-as-given", ["--scheduler", "foo"], 2, ["--scheduler 'foo'"]),
    ("dask-workers-with-a-scheduler-address", ["--dask", "tcp://127.0.0.1:1", "--dask-workers", "2"], 2,
     ["--dask-workers sizes --dask local"]),
    ("retries-negative", ["--retries", "-1"], 2, ["--retries"]),
    ("unknown-option", ["--frobnicate"], 2, ["--frobnicate"]),
    ("planner-counts-no-iterations", ["--planners", "AORRTC", "RRTstar"], 2, ["--planners", "AORRTC"]),
    ("checker-twice", ["--checkers", "dense", "dense"], 2, ["--checkers", "twice"]),
    ("resume-empty", ["--resume", ""], 2, ["--resume", "empty"]),
    ("queries-empty", ["--queries", ""], 2, ["--queries", "empty"]),
    ("name-too-long", ["--name", "x" * 300], 2, ["--name", "234 bytes"]),
    ("resume-bad-query-data", ["--resume", "{in}/bad_query_data"], 2, ["--resume", "query_data", "entry 0"]),
    ("resume-config-a-list", ["--resume", "{in}/config_list"], 2, ["--resume", "config"]),
    ("resume-config-without-seed", ["--resume", "{in}/no_seed"], 2, ["--resume", "no seed"]),
    ("resume-logs-a-file", ["--resume", "{in}/logs_a_file"], 2, ["--resume", "logs there is a file"]),
    ("resume-lock-a-folder", ["--resume", "{in}/lock_a_folder"], 2, ["--resume", ".lock there is a folder"]),
    ("resume-with-campaign-options", ["--resume", "{in}/not_a_campaign", "--samples", "30", "--seed", "4"], 2,
     ["--resume", "--samples, --seed would be ignored"]),
    ("anytime-queries-without-budgets", ["--anytime-queries", "2"], 2, ["--anytime-queries", "give --anytime"]),
    ("alt-checker-queries-with-one-validator", ["--checkers", "discrete", "--alt-checker-queries", "1"], 2,
     ["--alt-checker-queries", "has one (discrete)"]),
    ("alt-checker-samples-without-samples", ["--checkers", "batched", "discrete", "--samples", "--anytime", "1",
                                             "--alt-checker-samples", "20"], 2,
     ["--alt-checker-samples", "give --samples"]),
]


def _args(args: list[str], inputs: Path, out: Path) -> list[str]:
    base = ["bench", "--queries", str(inputs / "good.json"), "--samples", "20", "--anytime",
            "--planners", "RRTstar", "InformedRRTstar", "--workers", "1", "--out", str(out), "--no-progress"]
    if "--resume" in args:  # a resumed campaign's options are its campaign.json's: giving them is refused
        base = ["bench", "--workers", "1", "--no-progress"]
    return base + [a.format(**{"in": inputs}) for a in args]


@pytest.mark.parametrize(("args", "code", "names"), [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_bad_bench_input_is_refused_before_anything_is_created(inputs, tmp_path, args, code, names):
    out = tmp_path / "out"
    (out / "earlier").mkdir(parents=True)
    (out / "earlier" / "campaign.json").write_text('{"an": "earlier campaign"}\n')
    before_out, before_in, tree_in = snapshot(out), snapshot(inputs), _tree(inputs)
    proc = run_cli(_args(args, inputs, out), cwd=TESTS)
    assert_refused(proc, code, *[n.format(**{"in": inputs}) for n in names])
    assert snapshot(out) == before_out and _tree(out) == ["earlier", "earlier/campaign.json"]  # no results folder
    assert snapshot(inputs) == before_in and _tree(inputs) == tree_in  # existing files unchanged, nothing added


@pytest.mark.parametrize(("args", "names"), [(["--max-queries", "-3"], ["--max-queries"]),
                                             (["--out", "{in}/plain.txt"], ["--out", "plain.txt"])])
def test_the_experiment_script_refuses_the_same_way(inputs, tmp_path, args, names):
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=str(ROOT))
    argv = _args(args, inputs, tmp_path)[1:]
    before = snapshot(inputs)
    proc = subprocess.run([sys.executable, str(SCRIPT), *argv], cwd=TESTS, env=env, capture_output=True, text=True,
                          timeout=120, stdin=subprocess.DEVNULL)
    assert_refused(proc, 2, *[n.format(**{"in": inputs}) for n in names])
    assert _tree(tmp_path) == [] and snapshot(inputs) == before


def test_a_runtime_failure_is_exit_1_in_one_line_and_keeps_what_ran(inputs, tmp_path):
    args = _args(["--planners", "helpers.bench_standins:make_broken_factory", "RRTstar"], inputs, tmp_path)
    proc = run_cli(args, cwd=TESTS)
    assert_refused(proc, 1, "2 query(ies) lost", "this planner factory always fails", "--resume")
    assert proc.stderr.count("this planner factory always fails") == 1  # said once for the queries it lost
    (directory,) = tmp_path.iterdir()  # the campaign had started: its folder stays, with the reasons
    meta = json.loads((directory / "campaign.json").read_text())
    assert [f["qpos"] for f in meta["failed_tasks"]] == [0, 1] and meta["interrupted"] is False
