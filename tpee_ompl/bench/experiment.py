"""One query's experiments, in a worker process: seeding, the experiment list, one ``ompl.tools.Benchmark`` each.

Each (query, comparison, cap/budget, motion validator) is one OMPL experiment, on one
``SimpleSetup`` per experiment (same validity checker, motion-check resolution, objective and OMPL
seed for every planner):

* **iterations** (paper Table 4): every planner is capped at N samples/iterations.  dimension-RRT
  gets ``max_samples=N``; OMPL's planners (default settings) are stopped after exactly N
  iterations by :class:`~tpee_ompl.bench.planners.RecordingPlanner`.
* **anytime**: every planner gets the same wall-time budget (seconds).

Each experiment is written as an OMPL ``.log`` (Planner Arena format), its recorded data patched
first (:func:`~tpee_ompl.bench.database.patch_recorded_data`) with the post-run measurements of
the raw planner output: lengths (:func:`group_lengths`), dense validity, iterations, collision checks.
"""

from __future__ import annotations

import logging
import math
import os
import socket
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from ompl import tools as ot
from ompl import util as ou

from ..planning.paths import path_length, path_passes_motion_checks
from .database import failed_run_properties, pad_aborted_runs, patch_recorded_data
from .planners import PlannerContext, RecordingPlanner, planner_factory
from ..files import write_new_file
from .results import format_value

__all__ = ["experiment_specs", "group_lengths", "log_name", "run_query_task"]

log = logging.getLogger(__name__)


def group_lengths(waypoints: np.ndarray) -> tuple[float, float, float]:
    """Lengths of a joint-space path: (4-D, DOF1/DOF2 group, DOF3/DOF4 group), radians.

    waypoints : ndarray, shape (K, 4).  Each is the sum over segments of the Euclidean norm of the
    segment's components (all four, the first two, the last two).
    """
    W = np.asarray(waypoints, dtype=float)
    if W.ndim != 2 or W.shape[1] != 4:
        raise ValueError(f"waypoints must have shape (K, 4), got {W.shape}")
    return path_length(W), path_length(W[:, :2]), path_length(W[:, 2:])


# --------------------------------------------------------------------------- seeds, experiment list
_SEEDED: list[int] = []


def _seed_process(seed: int) -> None:
    if not _SEEDED:  # a second setSeed in one process only prints an error
        ou.RNG.setSeed(int(seed))
        _SEEDED.append(int(seed))
    elif _SEEDED[0] != int(seed):
        log.warning("OMPL was seeded with %d in this process, not %d: runs are not reproducible", _SEEDED[0], seed)


def _sub_seed(*parts: int) -> int:
    return int(np.random.SeedSequence([int(p) for p in parts]).generate_state(1)[0])


def experiment_specs(cfg: dict, qpos: int) -> list[dict]:
    """The experiments of the query at position ``qpos``: ``{comparison, checker, cap, budget}`` each.

    ``cfg`` is a :class:`~tpee_ompl.bench.config.CampaignConfig` as a dict.
    """
    specs = []
    for ci, checker in enumerate(cfg["checkers"]):
        if ci > 0 and cfg["alt_checker_queries"] is not None and qpos >= cfg["alt_checker_queries"]:
            continue
        caps = cfg["sample_caps"] if ci == 0 or cfg["alt_checker_caps"] is None else cfg["alt_checker_caps"]
        for cap in caps:
            specs.append({"comparison": "iterations", "checker": checker, "cap": int(cap), "budget": None})
    if cfg["anytime_queries"] is None or qpos < cfg["anytime_queries"]:
        for b in cfg["anytime_budgets"]:
            specs.append({"comparison": "anytime", "checker": cfg["checkers"][0] if cfg["checkers"] else "batched",
                          "cap": None, "budget": float(b)})
    return specs


def log_name(query: dict, qpos: int, spec: dict) -> str:
    """File name of an experiment's log, e.g. ``q003_iterations_batched_N500.log``."""
    tag = f"N{spec['cap']}" if spec["cap"] is not None else f"T{spec['budget']:g}s"
    return f"q{qpos:03d}_{spec['comparison']}_{spec['checker']}_{tag}.log"


# --------------------------------------------------------------------------- one query
def run_query_task(task: dict) -> dict:
    """Run the experiments of one query; return their OMPL logs as text plus per-run extras.

    ``task`` holds only plain data (OMPL objects cannot be pickled): ``config`` (dict of
    :class:`~tpee_ompl.bench.config.CampaignConfig`), ``query`` (dict), ``qpos`` (position in the
    set), ``query_set``, ``seed``, ``n_threads``, optionally ``specs`` (the experiments to run;
    default all) and ``log_dir``.  With ``log_dir`` each log is also written there as soon as its
    experiment ends (atomically, never over an existing file), so an interrupted campaign keeps it,
    and an experiment whose log is already there is skipped (a retried task runs only what its
    dead predecessor did not finish).

    Returns (JSON-able): ``qpos``, ``query_id``, ``logs`` ({file name: log text}), ``extras``
    ({file name: {planner: [per-run properties]}}), ``errors``, ``pid``, ``host``, ``elapsed``.
    """
    from ..model.wearer_arm import WearerArm

    t0 = time.perf_counter()
    cfg, query, qpos = task["config"], task["query"], int(task["qpos"])
    _seed_process(task["seed"])
    ou.setLogLevel(ou.LOG_WARN)
    robot = WearerArm(n_threads=task.get("n_threads"))
    log_dir = Path(task["log_dir"]) if task.get("log_dir") else None
    specs = task.get("specs") or experiment_specs(cfg, qpos)
    out: dict = {"qpos": qpos, "query_id": query["id"], "logs": {}, "extras": {}, "errors": {},
                 "pid": os.getpid(), "host": socket.gethostname()}
    from .ladder import Ladder, group_ladders

    # written by an earlier attempt of this task whose worker died
    specs = [s for s in specs if log_dir is None or not (log_dir / log_name(query, qpos, s)).is_file()]
    for group in group_ladders(specs, cfg.get("one_run_per_ladder", True), cfg["iteration_planners"]):
        ladder = Ladder(group) if len(group) > 1 else None  # one run at the largest cap gives every cap's log
        results = [_run_experiment(robot, cfg, task, group[-1], ladder)]
        if ladder is not None:
            results = (ladder.derived or [_run_experiment(robot, cfg, task, s) for s in group[:-1]]) + results
        for spec, (text, extras, error) in zip(group, results):
            fname = log_name(query, qpos, spec)
            out["logs"][fname], out["extras"][fname] = text, extras
            if error:
                out["errors"][fname] = error
            if log_dir is not None:
                write_new_file(log_dir / fname, text)
    out["elapsed"] = time.perf_counter() - t0
    return out


def _restore_ompl_output(before) -> None:
    """Undo what an aborted ``Benchmark.benchmark`` leaves: OMPL's output handler switched off.

    ``restorePreviousOutputHandler`` *swaps* the current and previous handlers, so it is called
    only when the handler is actually off (calling it after a normal run would silence OMPL).
    """
    if before is not None and ou.getOutputHandler() is None:
        ou.restorePreviousOutputHandler()
        if ou.getOutputHandler() is None:
            ou.useOutputHandler(before)


def _guarded(fn: Callable, *args) -> None:
    try:
        fn(*args)
    except Exception:  # noqa: BLE001 (an exception would abort benchmark())
        log.exception("benchmark event %s failed", getattr(fn, "__name__", fn))


def _experiment_parameters(robot, cfg: dict, task: dict, spec: dict, start: np.ndarray, goal: np.ndarray) -> dict:
    """The experiment's parameters (``"name TYPE": text``), columns of the ``experiments`` table."""
    query, cap, budget = task["query"], spec["cap"], spec["budget"]
    return {
        "comparison TEXT": spec["comparison"],
        "query_set TEXT": task["query_set"],
        "query_id TEXT": str(query["id"]),
        "query_index INTEGER": str(int(task["qpos"])),
        "from_sector INTEGER": str(query["from_sector"]),
        "to_sector INTEGER": str(query["to_sector"]),
        "sample_cap INTEGER": str(cap) if cap is not None else "0",
        "time_budget REAL": format_value(budget) if budget is not None else "0",
        "motion_validator TEXT": spec["checker"],
        "straight_length REAL": format_value(float(np.linalg.norm(goal - start))),
        "campaign_seed INTEGER": str(cfg["seed"]),
        "process_seed INTEGER": str(task["seed"]),
        "model_hash TEXT": robot.model_hash,
    }


def _path_properties(si, rec: dict, start: np.ndarray, goal: np.ndarray) -> dict:
    """Run properties measured on the raw path of a RecordingPlanner record (none without a path)."""
    W = rec.get("waypoints")
    if W is None or len(W) < 1:
        return {}
    l4, l12, l34 = group_lengths(W) if len(W) >= 2 else (0.0, 0.0, 0.0)
    ok = path_passes_motion_checks(si, W)
    best = rec["best_cost"]
    if best is None or not math.isfinite(float(best)):
        best = l4
    ends = bool(np.allclose(W[0], start, atol=1e-6) and np.allclose(W[-1], goal, atol=1e-6))
    return {"reaches_goal INTEGER": int(ends), "best_cost REAL": best, "length_dof12 REAL": l12,
            "length_dof34 REAL": l34, "raw_length REAL": l4, "path_valid_dense INTEGER": int(ok)}


def _run_experiment(robot, cfg: dict, task: dict, spec: dict, ladder=None) -> tuple[str, dict, str | None]:
    """One OMPL experiment; returns (log text, {planner: [run properties]}, benchmark error or None).

    Exceptions from Python callbacks never escape: planner exceptions are caught in
    :class:`~tpee_ompl.bench.planners.RecordingPlanner`, event-callback exceptions in the events,
    and anything else that aborts ``benchmark()`` (e.g. a Python validity checker raising while
    OMPL checks the path) restores OMPL's logging and records every run that did not finish as a
    failed run (status *crash*, ``planner_error`` = 1).
    With a :class:`~tpee_ompl.bench.ladder.Ladder`, the run also gives the logs of its smaller caps
    (``ladder.derived``).
    """
    from ..planning.setup import make_simple_setup

    query, qpos = task["query"], int(task["qpos"])
    start, goal = np.asarray(query["start"], float), np.asarray(query["goal"], float)
    ss = make_simple_setup(robot, start, goal, batched_motion_validator=spec["checker"] == "batched")
    si = ss.getSpaceInformation()
    cap, budget = spec["cap"], spec["budget"]
    name = (f"{spec['comparison']}_{task['query_set']}_q{qpos:03d}_"
            + (f"N{cap}" if cap is not None else f"T{budget:g}s") + f"_{spec['checker']}")
    bench = ot.Benchmark(ss, name)
    for k, v in _experiment_parameters(robot, cfg, task, spec, start, goal).items():
        pname, ptype = k.rsplit(" ", 1)
        bench.addExperimentParameter(pname, ptype, v)

    planners = cfg["iteration_planners"] if spec["comparison"] == "iterations" else cfg["anytime_planners"]
    wrappers = {}
    tag = cap if cap is not None else int(round(budget * 1000))
    tag = spec.get("seed_tag", tag)  # a separate run with a ladder's planner seeds (tests/bench/test_ladder.py)
    for k, pname in enumerate(planners):
        ctx = PlannerContext(query=query, max_samples=cap, seed=_sub_seed(cfg["seed"], qpos, k, tag))
        inner = planner_factory(pname)(si, ctx)
        w = (RecordingPlanner(si, inner, max_iterations=cap) if ladder is None
             else ladder.wrap(si, inner, cap, pname, ctx))
        wrappers[w.getName()] = w
        bench.addPlanner(w)

    records: dict[str, list[dict]] = {n: [] for n in wrappers}
    counter = {"before": 0}

    def pre_run(planner) -> None:
        counter["before"] = robot.collision_checks

    def post_run_props(planner) -> dict:
        checks = robot.collision_checks - counter["before"]
        rec = wrappers[planner.getName()].last
        props = {
            "collision_checks INTEGER": checks,
            "iterations INTEGER": rec["iterations"],
            "samples INTEGER": rec["samples"],
            "first_solution_time REAL": rec["first_solution_time"],
            "best_cost REAL": None,
            "length_dof12 REAL": None,
            "length_dof34 REAL": None,
            "raw_length REAL": None,
            "path_valid_dense INTEGER": 0,
            "reaches_goal INTEGER": 0,
            "planner_error INTEGER": int(rec["error"] is not None),
        }
        if rec.get("graph_states") is not None:  # OMPL's own columns, which it cannot fill through the wrapper
            props["graph states INTEGER"] = rec["graph_states"]
            props["graph motions INTEGER"] = rec["graph_motions"]
        props.update(_path_properties(si, rec, start, goal))
        return {"props": props, "progress": rec["progress"]}

    def post_run(planner, run) -> None:
        try:
            rec = post_run_props(planner)
        except Exception as exc:  # noqa: BLE001 (would abort benchmark())
            log.exception("post-run event failed for %s", planner.getName())
            rec = {"props": failed_run_properties(repr(exc)), "progress": []}
        records.setdefault(planner.getName(), []).append(rec)

    bench.setPreRunEvent(lambda p: _guarded(pre_run, p))
    bench.setPostRunEvent(post_run)
    req = ot.Request(
        maxTime=float(cfg["max_time"] if cap is not None else budget),
        maxMem=4096.0,
        runCount=int(cfg["runs"]),
        timeBetweenUpdates=0.05,
        displayProgress=False,
        saveConsoleOutput=False,
        simplify=bool(cfg["simplify"]),
    )
    handler = ou.getOutputHandler()
    error = None
    try:
        bench.benchmark(req)
    except Exception as exc:  # noqa: BLE001 (a Python callback raised inside OMPL)
        error = repr(exc)
        _restore_ompl_output(handler)
        log.error("benchmark %s aborted by %s; unfinished runs are recorded as failed", name, error)
    finally:
        _restore_ompl_output(handler)
        ou.setLogLevel(ou.LOG_WARN)
    if error is not None:
        pad_aborted_runs(bench, records, int(cfg["runs"]), error)
    patch_recorded_data(bench, wrappers, records, cap)
    with tempfile.TemporaryDirectory(prefix="tpee_log_") as tmp:
        path = Path(tmp) / "experiment.log"
        bench.saveResultsToFile(str(path))
        text = path.read_text()
    if ladder is not None:
        try:
            ladder.derived = ladder.derive(bench, ss, name, records, start, goal, bool(cfg["simplify"]),
                                           float(cfg["max_time"]))
        except Exception:  # noqa: BLE001 (the smaller caps then run separately)
            log.exception("checkpoint rows of %s failed; running its smaller caps separately", name)
    extras = {n: [{k.rsplit(" ", 1)[0]: v for k, v in r["props"].items()} for r in recs] for n, recs in records.items()}
    return text, extras, error
