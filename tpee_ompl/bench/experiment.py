"""One query's experiments, in a worker process: seeding, the experiment list, one ``ompl.tools.Benchmark`` each.

Each (query, comparison, cap/budget, motion validator) is one OMPL experiment, on one
``SimpleSetup`` per experiment (same validity checker, motion-check resolution and objective for every
planner; each planner's seed, and OMPL's seed generator when it is made and before each of its runs, from the
campaign seed, the query, its position in the list and the cap or budget (a ladder's one run: its largest cap's),
so a retried or resumed experiment draws the samples of an uninterrupted run, whatever ran before it):

* **iterations** (paper Table 4): every planner is capped at N samples/iterations.  dimension-RRT
  gets ``max_samples=N``; OMPL's planners (default settings) are stopped after exactly N
  iterations by :class:`~tpee_ompl.bench.planners.RecordingPlanner`.
* **anytime**: every planner gets the same wall-time budget (seconds).

Each experiment is written as an OMPL ``.log`` (Planner Arena format), its recorded data patched
first (:func:`~tpee_ompl.bench.database.patch_recorded_data`) with the post-run measurements of
the raw planner output: lengths (:func:`group_lengths`), dense validity, iterations, collision checks.
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import math
import os
import socket
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import tools as ot
from ompl import util as ou

from .._version import __version__
from ..files import write_new_file
from ..planning.paths import path_length, path_passes_motion_checks
from ..planning.space_layout import RealVectorLayout
from ..planning.setup import seed_ompl
from ..validation import sub_seed
from .database import NO_PATH_COLUMNS, failed_run_properties, log_text, pad_aborted_runs, patch_recorded_data
from .ladder import DeriveContext
from .planners import SINGLE_USE_PLANNERS, PlannerContext, RecordingPlanner, planner_factory
from .problems import Problem, get_problem
from .results import format_value, planner_name

__all__ = ["experiment_name", "experiment_specs", "group_lengths", "log_name", "run_query_task"]

log = logging.getLogger(__name__)


def group_lengths(waypoints: np.ndarray, first: Sequence[int] = (0, 1),
                  layout: RealVectorLayout | None = None) -> tuple[float, float, float]:
    """Lengths of a path: (whole, group ``first``, the other coordinates); the ``length_dof12``/``length_dof34`` columns.

    waypoints : ndarray, shape (K, n), n > 2 (the wearer: (K, 4), groups DOF1/DOF2 and DOF3/DOF4, radians).
    The whole length is in the space's metric (``layout.path_length``, what ``si.distance`` sums; default
    Euclidean); each group's is the sum over segments of the Euclidean norm of the segment's components
    in that group (SO2 components taken the short way round when ``layout`` has them).
    """
    W = np.asarray(waypoints, dtype=float)
    first = [int(i) for i in first]
    if W.ndim != 2 or W.shape[1] <= max(first) + 1:
        raise ValueError(f"waypoints must have shape (K, n) with n > {max(first) + 1}, got {W.shape}")
    rest = [i for i in range(W.shape[1]) if i not in first]
    if layout is None or layout.is_plain:
        return path_length(W), path_length(W[:, first]), path_length(W[:, rest])
    D = layout.delta(W[:-1], W[1:])
    return (layout.path_length(W), float(np.linalg.norm(D[:, first], axis=1).sum()),
            float(np.linalg.norm(D[:, rest], axis=1).sum()))


# --------------------------------------------------------------------------- seeds, experiment list
def _seed_planner(seed: int) -> None:
    """Set OMPL's seed generator just before a planner is made, so that an OMPL planner's random numbers depend
    on its own seed (campaign seed, query, position, cap or budget) and not on how many planners the process made
    before it: a task retried after its worker died, or a resumed campaign, runs only the experiments not yet
    logged, and they must give the rows an uninterrupted run gives."""
    seed_ompl(int(seed) or 1)  # (sub_seed can give 0, which OMPL refuses)


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
            headline = cfg["checkers"][0] if cfg["checkers"] else get_problem(cfg.get("problem", "wearer")).checkers[0]
            specs.append({"comparison": "anytime", "checker": headline,
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
    t0 = time.perf_counter()
    cfg, query, qpos = task["config"], task["query"], int(task["qpos"])
    seed_ompl(task["seed"])  # (each planner is seeded again before it is made)
    ou.setLogLevel(ou.LOG_WARN)
    log_dir = Path(task["log_dir"]) if task.get("log_dir") else None
    given = {log_name(query, qpos, s): s for s in (task.get("specs") or experiment_specs(cfg, qpos))}
    out: dict = {"qpos": qpos, "query_id": query["id"], "logs": {}, "extras": {}, "errors": {},
                 "pid": os.getpid(), "host": socket.gethostname()}
    from .anytime_ladder import AnytimeLadder, group_anytime_ladders
    from .ladder import Ladder, group_ladders

    # not those written by an earlier attempt of this task whose worker died
    wanted = {n for n in given if log_dir is None or not (log_dir / n).is_file()}
    # Ladders are grouped from all the query's experiments: a ladder with a missing member runs whole, with the
    # seeds of its largest cap (budget), so the missing log holds the rows of an uninterrupted campaign.
    specs = {log_name(query, qpos, s): s for s in experiment_specs(cfg, qpos)}
    specs.update(given)  # a task's own spec (a test's seed_tag) stands for the configuration's
    groups = group_ladders(list(specs.values()), cfg.get("one_run_per_ladder", True), cfg["iteration_planners"])
    for group in group_anytime_ladders(groups, cfg.get("one_run_per_anytime_ladder", True)):
        if not any(log_name(query, qpos, s) in wanted for s in group):
            continue
        ladder = None  # one run at the largest cap (longest budget) gives every cap's (budget's) log
        if len(group) > 1:
            ladder = (Ladder(group) if group[0]["comparison"] == "iterations"
                      else AnytimeLadder(group, lambda spec, names: _run_separately(cfg, task, spec, names)))
        results = [_run_experiment(cfg, task, group[-1], ladder)]
        if ladder is not None:
            results = (ladder.derived or [_run_experiment(cfg, task, s) for s in group[:-1]]) + results
        for spec, (text, extras, error) in zip(group, results):
            fname = log_name(query, qpos, spec)
            if fname not in wanted:  # a member whose log exists: it stays as it is
                continue
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


def experiment_name(query_set: str, spec: dict) -> str:
    """The OMPL experiment name: comparison, query set, cap or budget and validator, the same for every query.

    Planner Arena pools the runs of experiments with one name (its "problem") and offers the experiment
    parameters (``query_id``, ...) as filters within it, so a planner's runs at one cap are one box over
    the campaign's queries rather than one point per query."""
    setting = f"N{spec['cap']}" if spec["cap"] is not None else f"T{spec['budget']:g}s"
    return f"{spec['comparison']}_{query_set}_{setting}_{spec['checker']}"


def _experiment_parameters(cfg: dict, task: dict, spec: dict, straight: float, model_hash: str) -> dict:
    """The experiment's parameters (``"name TYPE": text``), columns of the ``experiments`` table.

    Sectors are 0 for problems without them; ``straight_length`` is ``si.distance(start, goal)``.
    """
    query, cap, budget = task["query"], spec["cap"], spec["budget"]
    return {
        "comparison TEXT": spec["comparison"],
        "query_set TEXT": task["query_set"],
        "query_id INTEGER": str(int(query["id"])),
        "query_index INTEGER": str(int(task["qpos"])),
        "from_sector INTEGER": str(int(query.get("from_sector", 0))),
        "to_sector INTEGER": str(int(query.get("to_sector", 0))),
        "sample_cap INTEGER": str(cap) if cap is not None else "0",
        "time_budget REAL": format_value(budget) if budget is not None else "0",
        "motion_validator TEXT": spec["checker"],
        "straight_length REAL": format_value(float(straight)),
        "campaign_seed INTEGER": str(cfg["seed"]),
        "process_seed INTEGER": str(task["seed"]),
        "model_hash TEXT": str(model_hash),
        # the log's version line is OMPL's; this is the package's, with its git commit when run from a checkout
        "tpee_ompl_version TEXT": task.get("code_version") or __version__,
    }


def _path_properties(si, rec: dict, start: np.ndarray, goal: np.ndarray, first: Sequence[int],
                     layout: RealVectorLayout) -> dict:
    """Run properties measured on the raw path of a RecordingPlanner record (none without a path)."""
    W = rec.get("waypoints")
    if W is None or len(W) < 1:
        return {}
    ends = bool(np.all(np.abs(layout.delta(W[0], start)) <= 1e-6) and np.all(np.abs(layout.delta(W[-1], goal)) <= 1e-6))
    # a path that never leaves its first state and stops short of the goal is no path to measure: AORRTC's
    # timeout answer (its start alone) and its "zero-length path" with status invalid goal (ompl/ompl#1420)
    if not ends and not np.any(np.abs(layout.delta(W[:1], W)) > 0.0):
        return {}
    l4, l12, l34 = group_lengths(W, first, layout) if len(W) >= 2 else (0.0, 0.0, 0.0)
    ok = path_passes_motion_checks(si, W if layout.is_plain else layout.to_path(si, W))
    # a path short of the goal has no best cost, whatever the planner's bestCost() says (AORRTC's is 0 then);
    # a planner without bestCost() (RRTConnect): its path's length
    best = rec["best_cost"] if ends else None
    if ends and (best is None or not math.isfinite(float(best))):
        best = l4
    return {"reaches_goal INTEGER": int(ends), "best_cost REAL": best, "length_dof12 REAL": l12,
            "length_dof34 REAL": l34, "raw_length REAL": l4, "path_valid_dense INTEGER": int(ok)}


def _run_separately(cfg: dict, task: dict, spec: dict, planners: list[str]) -> tuple[list, dict, str | None]:
    """An experiment of only ``planners`` (anytime ladder: the budgets they cannot be read at); returns
    its recorded planners (detached copies), extras and error."""
    sink: dict = {}
    _, extras, error = _run_experiment(cfg, task, spec, only=planners, sink=sink)
    return sink["planners"], extras, error


@dataclasses.dataclass(frozen=True)
class _Setup:
    """One experiment's problem and OMPL set-up, shared by its planners, run events and ladder; ``checker``
    is the problem's (it counts ``collision_checks`` and has ``model_hash``)."""

    problem: Problem
    ss: og.SimpleSetup
    si: ob.SpaceInformation
    checker: Any
    layout: RealVectorLayout
    start: np.ndarray
    goal: np.ndarray

    def path_properties(self, si: ob.SpaceInformation, rec: dict, start: np.ndarray, goal: np.ndarray) -> dict:
        """:func:`_path_properties` with this problem's first group and state layout."""
        return _path_properties(si, rec, start, goal, self.problem.groups[0], self.layout)


def _run_experiment(cfg: dict, task: dict, spec: dict, ladder=None, only: list[str] | None = None,
                    sink: dict | None = None) -> tuple[str, dict, str | None]:
    """One OMPL experiment; returns (log text, {planner: [run properties]}, benchmark error or None).

    Exceptions from Python callbacks never escape: planner exceptions are caught in
    :class:`~tpee_ompl.bench.planners.RecordingPlanner`, event-callback exceptions in the events,
    and anything else that aborts ``benchmark()`` (e.g. a Python validity checker raising while
    OMPL checks the path) restores OMPL's logging and records every run that did not finish as a
    failed run (status *crash*, ``planner_error`` = 1).
    With a :class:`~tpee_ompl.bench.ladder.Ladder` (:class:`~tpee_ompl.bench.anytime_ladder.AnytimeLadder`),
    the run also gives the logs of its smaller caps (shorter budgets) in ``ladder.derived``.  ``only``: run
    only these planners (same seeds as in the full experiment); ``sink["planners"]`` then receives detached
    copies of the recorded planners.
    """
    setup = _make_setup(cfg, task, spec)
    name = experiment_name(task["query_set"], spec)
    bench = _make_benchmark(cfg, task, spec, setup, name)
    wrappers, seeds = _add_planners(cfg, task, spec, setup, bench, ladder, only)
    records: dict[str, list[dict]] = {n: [] for n in wrappers}
    _set_run_events(bench, setup, wrappers, records, seeds)
    error = _benchmark(bench, _request(cfg, spec), name)
    if error is not None:
        pad_aborted_runs(bench, records, int(cfg["runs"]), error)
    patch_recorded_data(bench, wrappers, records, spec["cap"], int(task["seed"]))
    text = log_text(bench)
    if sink is not None:
        from .anytime_ladder import copy_planner

        sink["planners"] = [copy_planner(pl) for pl in bench.getRecordedExperimentData().planners]
    if ladder is not None:
        _derive_ladder(cfg, setup, ladder, bench, name, records)
    extras = {n: [{k.rsplit(" ", 1)[0]: v for k, v in r["props"].items()} for r in recs] for n, recs in records.items()}
    return text, extras, error


def _make_setup(cfg: dict, task: dict, spec: dict) -> _Setup:
    """The problem's ``SimpleSetup`` for the query and the experiment's motion validator."""
    problem = get_problem(cfg.get("problem", "wearer"))
    start, goal = np.asarray(task["query"]["start"], float), np.asarray(task["query"]["goal"], float)
    ss, checker = problem.make_setup(task["query"], spec["checker"], task.get("n_threads"))
    si = ss.getSpaceInformation()
    return _Setup(problem, ss, si, checker, RealVectorLayout(si.getStateSpace()), start, goal)


def _make_benchmark(cfg: dict, task: dict, spec: dict, setup: _Setup, name: str) -> ot.Benchmark:
    """The experiment's ``ot.Benchmark``, with its parameters (:func:`_experiment_parameters`) and no planner yet."""
    si, layout = setup.si, setup.layout
    straight = si.distance(layout.write(si.allocState(), setup.start), layout.write(si.allocState(), setup.goal))
    bench = ot.Benchmark(setup.ss, name)
    for k, v in _experiment_parameters(cfg, task, spec, straight, setup.checker.model_hash).items():
        pname, ptype = k.rsplit(" ", 1)
        bench.addExperimentParameter(pname, ptype, v)
    return bench


def _add_planners(cfg: dict, task: dict, spec: dict, setup: _Setup, bench: ot.Benchmark, ladder,
                  only: list[str] | None) -> tuple[dict, dict[str, int]]:
    """Add the comparison's planners (only those in ``only``, if given) to ``bench``; returns their wrappers and
    their seeds by name.

    A planner's seed depends on its position in the comparison's full list, so it is the same with ``only``; OMPL's
    seed generator is set to it before the planner is made (:func:`_seed_planner`), and to ``sub_seed(seed, run)``
    before each of its runs (:func:`_set_run_events`).
    """
    cap, budget = spec["cap"], spec["budget"]
    planners = cfg["iteration_planners"] if spec["comparison"] == "iterations" else cfg["anytime_planners"]
    tag = cap if cap is not None else int(round(budget * 1000))
    tag = spec.get("seed_tag", tag)  # a separate run with a ladder's planner seeds (tests/bench/test_ladder.py)
    wrappers: dict = {}
    seeds: dict[str, int] = {}
    for k, pname in enumerate(planners):
        if only is not None and pname not in only:
            continue
        ctx = PlannerContext(query=task["query"], max_samples=cap, seed=sub_seed(cfg["seed"], int(task["qpos"]), k, tag),
                             problem=setup.problem.name)
        w = _wrap_planner(pname, ctx, spec, setup, ladder, wrappers)
        wrappers[w.getName()] = w
        seeds[w.getName()] = ctx.seed
        bench.addPlanner(w)
    return wrappers, seeds


def _wrap_planner(pname: str, ctx: PlannerContext, spec: dict, setup: _Setup, ladder, earlier: dict) -> ob.Planner:
    """Planner ``pname``'s recording wrapper (the ladder's, with a ladder).

    Raises ValueError when its factory returns no ``ob.Planner`` or one named like a planner in ``earlier``.
    """
    factory = planner_factory(pname)
    _seed_planner(ctx.seed)
    inner = factory(setup.si, ctx)
    if not isinstance(inner, ob.Planner):
        raise ValueError(f"planner factory {pname!r} returned {type(inner).__name__}, not an ompl.base.Planner")
    if inner.getName() in {planner_name(n) for n in earlier} | set(earlier):
        raise ValueError(f"planner factory {pname!r} makes a planner named {inner.getName()!r} like an earlier one "
                         "of the experiment: the log keys runs by name (give it another name, setName)")
    read = None if setup.layout.is_plain else setup.layout.read
    renew = functools.partial(factory, setup.si, ctx) if pname in SINGLE_USE_PLANNERS else None
    if ladder is None:
        return RecordingPlanner(setup.si, inner, max_iterations=spec["cap"], read=read, checker=setup.checker,
                                renew=renew, deadline=spec["budget"])
    return ladder.wrap(setup.si, inner, spec["cap"], pname, ctx, checker=setup.checker, read=read, renew=renew)


def _set_run_events(bench: ot.Benchmark, setup: _Setup, wrappers: dict, records: dict[str, list[dict]],
                    seeds: dict[str, int]) -> None:
    """Set ``bench``'s run events: before each run, reset the objective's cost threshold, note the collision checks
    so far, set OMPL's seed generator from the planner's seed and the run's index and renew a used single-use
    planner (:meth:`~tpee_ompl.bench.planners.RecordingPlanner.renew_if_used`); after it, append its properties
    and progress (:func:`_run_properties`) to ``records``.

    The seed before each run: an OMPL planner allocates its sampler (and that sampler's random numbers) when it
    first solves after ``clear()``, so without it a planner's samples depended on what ran before it in the
    process, OMPL's path simplification of the previous planner's path included (it draws seeds from the
    generator as the path asks): RRT*'s rows differed between a ladder and a separate capped run once
    dimension-RRT's path before it changed, and a retried experiment of some planners could not repeat them."""
    checks_before = {"value": 0}
    pdef = setup.ss.getProblemDefinition()
    objective = pdef.getOptimizationObjective() if pdef.hasOptimizationObjective() else None
    threshold = objective.getCostThreshold().value() if objective is not None else None

    def pre_run(planner) -> None:
        checks_before["value"] = setup.checker.collision_checks
        if objective is not None:  # AORRTC lowers the shared objective's threshold to its own cost as it runs:
            objective.setCostThreshold(ob.Cost(threshold))  # the next planner (BIT*) then stopped once it beat that

    def post_run(planner, run) -> None:
        try:
            last = wrappers[planner.getName()].last
            rec = {"props": _run_properties(setup, last, checks_before["value"]),
                   "progress": _path_costs(last["progress"], float(setup.layout.distance(setup.start, setup.goal)))}
        except Exception as exc:  # noqa: BLE001 (would abort benchmark())
            log.exception("post-run event failed for %s", planner.getName())
            rec = {"props": failed_run_properties(repr(exc)), "progress": []}
        records.setdefault(planner.getName(), []).append(rec)

    def seed_run(planner) -> None:  # apart from pre_run: a failure here must not skip the threshold's reset
        name = planner.getName()
        _seed_planner(sub_seed(seeds[name], len(records.get(name, ()))))
        wrappers[name].renew_if_used()  # a single-use planner's fresh instance draws from the run's seed

    def before_run(planner) -> None:
        _guarded(pre_run, planner)
        _guarded(seed_run, planner)

    bench.setPreRunEvent(before_run)
    bench.setPostRunEvent(post_run)


def _path_costs(progress: list, shortest: float) -> list:
    """The progress rows [(t, best cost, n)] whose cost a path from start to goal can have: none is shorter than
    ``shortest``, the start-goal distance (AORRTC's bestCost() is 0 once its answer is its start alone,
    ompl/ompl#1420; such rows drew its progress curve at cost 0).  Rows without a path (cost inf) stay."""
    return [row for row in progress if row[1] >= shortest * (1.0 - 1e-9)]


def _run_properties(setup: _Setup, rec: dict, checks_before: int) -> dict:
    """The columns of one run from its RecordingPlanner record: counts, then the raw path's (:func:`_path_properties`)."""
    # the run's own checks: not those of OMPL's simplification and path checks after it
    end = rec.get("checks_end")
    checks = (end if end is not None else setup.checker.collision_checks) - checks_before
    props = {
        "collision_checks INTEGER": checks,
        "iterations INTEGER": rec["iterations"],
        "samples INTEGER": rec["samples"],
        "first_solution_time REAL": rec["first_solution_time"],
        **NO_PATH_COLUMNS,
        "planner_error INTEGER": int(rec["error"] is not None),
    }
    # OMPL's own columns, which it cannot fill through the wrapper: NULL where unknown (a Python planner's graph),
    # and the valid share of the run's motions (OMPL's counters stay at 0 under a Python motion validator)
    props["graph states INTEGER"] = rec.get("graph_states")
    props["graph motions INTEGER"] = rec.get("graph_motions")
    props["valid segment fraction REAL"] = rec.get("valid_fraction")
    props.update(setup.path_properties(setup.si, rec, setup.start, setup.goal))
    if not props["reaches_goal INTEGER"]:  # never held an exact path (AORRTC's finite bestCost() without one)
        props["first_solution_time REAL"] = None
    return props


def _request(cfg: dict, spec: dict) -> ot.Request:
    """The benchmark request: the safety time limit under an iteration cap, else the time budget."""
    return ot.Request(
        maxTime=float(cfg["max_time"] if spec["cap"] is not None else spec["budget"]),
        maxMem=4096.0,
        runCount=int(cfg["runs"]),
        timeBetweenUpdates=0.05,
        displayProgress=False,
        saveConsoleOutput=False,
        simplify=bool(cfg["simplify"]),
    )


def _benchmark(bench: ot.Benchmark, req: ot.Request, name: str) -> str | None:
    """Run ``bench``; returns None, or the exception that aborted it (OMPL's output then restored)."""
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
    return error


def _derive_ladder(cfg: dict, setup: _Setup, ladder, bench: ot.Benchmark, name: str, records: dict) -> None:
    """Set ``ladder.derived`` to the logs of its smaller caps (shorter budgets), read from this run.

    On failure it stays as it was, and the caller runs those experiments separately.
    """
    try:
        ctx = DeriveContext(setup.ss, setup.start, setup.goal, bool(cfg["simplify"]), float(cfg["max_time"]),
                            setup.path_properties)
        ladder.derived = ladder.derive(bench, name, records, ctx)
    except Exception:  # noqa: BLE001 (the smaller caps then run separately)
        log.exception("checkpoint rows of %s failed; running its smaller caps (budgets) separately", name)
