"""Benchmark campaigns: dimension-RRT against OMPL's planners through ``ompl.tools.Benchmark``.

Two comparisons, both on the same ``SimpleSetup`` per query (same validity checker, motion-check
resolution, objective and OMPL seed):

* **iterations** (paper Table 4): every planner is capped at N samples/iterations, N in
  ``sample_caps``.  dimension-RRT gets ``max_samples=N``; OMPL's ``RRTstar`` (default settings) is
  stopped after exactly N iterations by :class:`RecordingPlanner`, a thin wrapper that ORs a
  termination condition on ``numIterations()`` into the benchmark's own one.
* **anytime**: every planner gets the same wall-time budget (``anytime_budgets``, seconds).

Each (query, comparison, cap/budget, motion validator) is one OMPL experiment written to its own
``.log`` (Planner Arena format); at the end every finished log goes into one SQLite database built
with ``ompl.tools.readBenchmarkLog``/``computeViews`` (what ``ompl_benchmark_statistics`` runs).

Every planner runs inside :class:`RecordingPlanner`, which keeps the planner's *raw* output path
(OMPL simplifies the solution in place before the post-run event, so the event can only see the
simplified path) and records progress.  After ``benchmark()`` and before saving, the recorded
experiment data are patched (see ``docs/benchmark.md``) so that every planner's rows have
``best_cost``, ``iterations``, ``samples``, ``collision_checks``, ``length_dof12``,
``length_dof34``, ``path_valid_dense`` and ``first_solution_time``; the wrapped planner's settings
go to ``plannerConfigs`` and the recorded progress to the ``progress`` table.

``solution_length`` in the database is the raw planner output (OMPL's default ``simplify=True``
only adds the ``simplified_*`` columns); the report uses the raw length, like the paper.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import datetime as _dt
import importlib
import io
import json
import logging
import math
import os
import platform
import signal
import socket
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..resources import data_path

__all__ = [
    "ANYTIME_PLANNERS",
    "CampaignConfig",
    "CampaignResult",
    "ITERATION_PLANNERS",
    "PLANNER_FACTORIES",
    "PlannerContext",
    "RecordingPlanner",
    "build_database",
    "build_parser",
    "group_lengths",
    "load_query_set",
    "main",
    "make_results_dir",
    "package_versions",
    "run_campaign",
    "resume_campaign",
    "run_query_task",
    "write_new_file",
    "stratified_subset",
]

log = logging.getLogger(__name__)

ITERATION_PLANNERS = ("DimensionRRT", "RRTstar")
"""Planners of the iteration-matched (Table 4) comparison: dimension-RRT first, the reference second."""
ANYTIME_PLANNERS = ("DimensionRRT", "RRTstar", "InformedRRTstar", "RRTConnect", "AORRTC", "BITstar")
"""Planners of the time-matched comparison."""
CHECKERS = ("batched", "discrete")
"""Motion validators: one batched Pinocchio call per motion, or OMPL's DiscreteMotionValidator."""
PROGRESS_PROPERTIES = ["best cost REAL", "iterations INTEGER", "time REAL"]  # sorted, as OMPL's map
REPO_ROOT = Path(__file__).resolve().parent.parent
QUERY_DIR = data_path("queries")


# --------------------------------------------------------------------------- configuration
@dataclass(frozen=True)
class CampaignConfig:
    """What one campaign runs.  Times in seconds, caps in samples (= RRT* iterations)."""

    name: str = "bench"
    """Folder suffix: ``<out>/<UTC timestamp>_<name>/``."""
    queries: str = "planning_necessary"
    """Query-set name (``experiments/queries/<name>.json``) or a JSON file path."""
    sample_caps: tuple[int, ...] = (500, 1000, 1500, 2000, 2500)
    iteration_planners: tuple[str, ...] = ITERATION_PLANNERS
    checkers: tuple[str, ...] = ("batched", "discrete")
    """Motion validators for the iteration comparison; the first is the headline configuration."""
    alt_checker_queries: int | None = None
    """Queries (first k) that also run with the non-headline validators; None = all."""
    alt_checker_caps: tuple[int, ...] | None = None
    """Caps for the non-headline validators; None = all ``sample_caps``."""
    anytime_budgets: tuple[float, ...] = (0.1, 0.5, 1.0, 2.0)
    anytime_planners: tuple[str, ...] = ANYTIME_PLANNERS
    anytime_queries: int | None = None
    """Queries (first k) of the anytime comparison; None = all."""
    max_queries: int | None = None
    """Use k queries, round-robin over sector pairs (:func:`stratified_subset`; None = all)."""
    runs: int = 1
    """Runs per planner per experiment."""
    workers: int = 1
    """Worker processes (one fresh process per query); 0 runs in this process (tests)."""
    seed: int = 1
    """Campaign seed; query k's process seeds OMPL with ``seed + k``."""
    out: str = "results"
    max_time: float = 300.0
    """Safety time limit per iteration-capped run (s); a run hitting it counts as a failure."""
    simplify: bool = True
    """OMPL's default; ``solution_length`` stays the raw length either way."""

    def __post_init__(self) -> None:
        if not self.sample_caps and not self.anytime_budgets:
            raise ValueError("nothing to run: give sample caps or anytime budgets")
        if any(int(n) < 1 for n in self.sample_caps):
            raise ValueError(f"sample caps must be >= 1, got {self.sample_caps}")
        if any(not (b > 0 and math.isfinite(b)) for b in self.anytime_budgets):
            raise ValueError(f"anytime budgets must be finite and > 0, got {self.anytime_budgets}")
        for c in self.checkers:
            if c not in CHECKERS:
                raise ValueError(f"unknown motion validator {c!r}: choose from {CHECKERS}")
        if self.sample_caps and not self.checkers:
            raise ValueError("give at least one motion validator")
        if self.workers < 0 or self.runs < 1:
            raise ValueError("workers must be >= 0 and runs >= 1")


@dataclass
class CampaignResult:
    """Where a campaign wrote its files."""

    directory: Path
    logs: list[Path]
    database: Path | None
    interrupted: bool
    report: dict = field(default_factory=dict)
    skipped_logs: list[Path] = field(default_factory=list)
    """Corrupt logs left out of the database (reported by name)."""
    plots: list[Path] = field(default_factory=list)


@dataclass(frozen=True)
class PlannerContext:
    """What a planner factory may use: the query (plain dict), the cap and a seed."""

    query: dict
    max_samples: int | None
    seed: int


PlannerFactory = Callable[["object", PlannerContext], "object"]


# --------------------------------------------------------------------------- planners
def _native(cls_name: str) -> PlannerFactory:
    def make(si, ctx: PlannerContext):
        from ompl import geometric as og

        return getattr(og, cls_name)(si)  # OMPL's defaults, never changed

    make.__name__ = f"make_{cls_name}"
    return make


def _dimension_rrt(si, ctx: PlannerContext):
    from ..planning.tpee import tpee_dimension_rrt

    q = ctx.query
    return tpee_dimension_rrt(si, int(q["from_sector"]), int(q["to_sector"]), max_samples=ctx.max_samples, seed=ctx.seed)


PLANNER_FACTORIES: dict[str, PlannerFactory] = {
    "DimensionRRT": _dimension_rrt,
    **{n: _native(n) for n in ("RRTstar", "InformedRRTstar", "RRTConnect", "AORRTC", "BITstar", "RRT", "PRMstar")},
}
"""Planner name -> factory ``(si, PlannerContext) -> ob.Planner``.  A name ``module:function`` is
imported instead (so worker processes can build planners defined elsewhere, e.g. test stand-ins)."""


def _factory(name: str) -> PlannerFactory:
    if name in PLANNER_FACTORIES:
        return PLANNER_FACTORIES[name]
    if ":" in name:
        mod, _, attr = name.partition(":")
        return getattr(importlib.import_module(mod), attr)
    raise ValueError(f"unknown planner {name!r}: choose from {sorted(PLANNER_FACTORIES)} or give module:function")


def _parse_settings(text: str) -> dict[str, str]:
    out = {}
    for line in text.splitlines():
        k, sep, v = line.partition(" = ")
        if sep and k.strip() and " " not in k.strip():
            out[k.strip()] = v.strip()
    return out


def _planner_settings(p) -> dict[str, str]:
    if hasattr(p, "settings"):
        return {str(k): str(v) for k, v in p.settings().items()}
    try:
        return _parse_settings(p.printSettings())
    except Exception:  # noqa: BLE001 (bindings differ per planner)
        return {}


def _make_wrapper_class():
    from ompl import base as ob

    class RecordingPlanner(ob.Planner):
        """Runs an inner planner, caps its iterations, keeps its raw path and records progress.

        Parameters
        ----------
        si : ob.SpaceInformation
        inner : ob.Planner
            Native OMPL planner or Python planner (``last_run_stats()`` is used when present).
        max_iterations : int or None
            Stop after this many ``inner.numIterations()`` (native planners only; Python planners
            get their cap through their factory).
        progress_period : float, seconds
            Progress sampling period for native planners exposing ``bestCost``/``numIterations``.
        """

        def __init__(self, si, inner, max_iterations: int | None = None, progress_period: float = 0.05) -> None:
            super().__init__(si, inner.getName())
            self.inner = inner
            self.max_iterations = max_iterations
            self.progress_period = float(progress_period)
            self._native_stats = hasattr(inner, "numIterations") and not hasattr(inner, "last_run_stats")
            if max_iterations is not None and not hasattr(inner, "last_run_stats") and not hasattr(inner, "numIterations"):
                raise ValueError(f"{inner.getName()} has no numIterations(): it cannot be iteration-capped")
            self.last: dict = {}

        def setup(self) -> None:  # noqa: D102 (OMPL override)
            super().setup()
            self._setup_error = None
            try:  # an exception escaping to C++ would abort the whole benchmark
                self.inner.setProblemDefinition(self.getProblemDefinition())
                self.inner.setup()
            except Exception as exc:  # noqa: BLE001
                log.exception("planner %s: setup failed", self.inner.getName())
                self._setup_error = repr(exc)

        def clear(self) -> None:  # noqa: D102 (OMPL override)
            super().clear()
            try:
                self.inner.clear()
            except Exception:  # noqa: BLE001
                log.exception("planner %s: clear failed", self.inner.getName())

        def solve(self, ptc):  # noqa: D102 (OMPL override)
            from ompl import base as ob

            inner, cap = self.inner, self.max_iterations
            t0 = time.perf_counter()
            progress: list[tuple[float, float, int]] = []
            state = {"next": 0.0}
            has_cost = hasattr(inner, "bestCost")

            def stop() -> bool:
                it = inner.numIterations()
                now = time.perf_counter() - t0
                if has_cost and now >= state["next"]:
                    progress.append((now, inner.bestCost().value(), it))
                    state["next"] = now + self.progress_period
                return cap is not None and it >= cap

            error = getattr(self, "_setup_error", None)
            try:
                if error is not None:
                    raise RuntimeError(f"setup failed: {error}")
                if self._native_stats:
                    cond = ob.plannerOrTerminationCondition(ptc, ob.PlannerTerminationCondition(stop))
                    status = inner.solve(cond)
                else:
                    status = inner.solve(ptc)
            except Exception as exc:  # noqa: BLE001 (an exception would abort the whole benchmark)
                log.exception("planner %s failed", inner.getName())
                error = repr(exc)
                status = ob.PlannerStatus(ob.PlannerStatus.CRASH)
            elapsed = time.perf_counter() - t0
            pdef = self.getProblemDefinition()
            waypoints = None
            if error is None and pdef.hasSolution():
                path = pdef.getSolutionPath()
                waypoints = np.array([[s[i] for i in range(4)] for s in path.getStates()], dtype=float)
            stats: dict = {}
            if hasattr(inner, "last_run_stats"):
                with contextlib.suppress(Exception):
                    stats = dict(inner.last_run_stats() or {})
                progress = [(float(t), float(c), int(n)) for t, c, n in stats.get("progress", [])]
                iterations = stats.get("iterations")
                samples = stats.get("samples", iterations)
                best = stats.get("best_cost")
                first = stats.get("first_solution_time")
            else:
                iterations = inner.numIterations() if hasattr(inner, "numIterations") else None
                samples = iterations
                best = inner.bestCost().value() if has_cost else None
                if has_cost:
                    progress.append((elapsed, best, iterations))
                finite = [t for t, c, _ in progress if math.isfinite(c)]
                first = finite[0] if finite else None
            self.last = {
                "waypoints": waypoints,
                "iterations": iterations,
                "samples": samples,
                "best_cost": best,
                "first_solution_time": first,
                "progress": progress,
                "error": error,
            }
            return status

    return RecordingPlanner


_WRAPPER = None


def RecordingPlanner(si, inner, max_iterations: int | None = None, progress_period: float = 0.05):  # noqa: N802
    """Create the wrapper planner (class built lazily so importing this module needs no OMPL)."""
    global _WRAPPER
    if _WRAPPER is None:
        _WRAPPER = _make_wrapper_class()
    return _WRAPPER(si, inner, max_iterations, progress_period)


# --------------------------------------------------------------------------- path metrics
def group_lengths(waypoints: np.ndarray) -> tuple[float, float, float]:
    """Lengths of a joint-space path: (4-D, DOF1/DOF2 group, DOF3/DOF4 group), radians.

    waypoints : ndarray, shape (K, 4).  Each is the sum over segments of the Euclidean norm of the
    segment's components (all four, the first two, the last two).
    """
    W = np.asarray(waypoints, dtype=float)
    if W.ndim != 2 or W.shape[1] != 4:
        raise ValueError(f"waypoints must have shape (K, 4), got {W.shape}")
    d = np.diff(W, axis=0)
    return (
        float(np.linalg.norm(d, axis=1).sum()),
        float(np.linalg.norm(d[:, :2], axis=1).sum()),
        float(np.linalg.norm(d[:, 2:], axis=1).sum()),
    )


def _fmt(v) -> str:
    if v is None:
        return ""
    if isinstance(v, str):
        return v
    if isinstance(v, (bool, np.bool_)):
        return str(int(v))
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    v = float(v)
    if math.isnan(v):
        return "nan"
    if math.isinf(v):
        return "inf"
    return repr(v)


# --------------------------------------------------------------------------- queries
def load_query_set(name_or_path: str) -> tuple[str, list[dict]]:
    """The set's name and its queries as plain dicts (picklable): id, from/to sector, start, goal."""
    try:
        from ..model.queries import load_queries
    except ImportError:
        load_queries = None
    path = Path(name_or_path)
    if not path.suffix and not path.exists():
        path = QUERY_DIR / f"{name_or_path}.json"
    name = path.stem
    if path.is_file():
        with contextlib.suppress(Exception):
            name = json.loads(path.read_text()).get("name", name)
    if load_queries is not None:
        qs = load_queries(str(path) if path.is_file() else name_or_path)
        rows = [
            {
                "id": q.id,
                "from_sector": int(q.from_sector),
                "to_sector": int(q.to_sector),
                "start": [float(x) for x in q.start],
                "goal": [float(x) for x in q.goal],
            }
            for q in qs
        ]
        return name, rows
    if not path.is_file():
        raise FileNotFoundError(f"query set {name_or_path!r} not found (looked for {path})")
    data = json.loads(path.read_text())
    rows = [
        {
            "id": q["id"],
            "from_sector": int(q["from_sector"]),
            "to_sector": int(q["to_sector"]),
            "start": [float(x) for x in q["start"]],
            "goal": [float(x) for x in q["goal"]],
        }
        for q in data["queries"]
    ]
    return data.get("name", name), rows


def stratified_subset(queries: list[dict], k: int | None) -> list[dict]:
    """All queries reordered round-robin over (from, to) sector pairs, then the first k.

    The first k of a set ordered pair by pair would cover only a few pairs; round-robin keeps every
    pair represented (24 of the 120 planning-necessary queries = 2 per ordered pair).
    """
    groups: dict[tuple[int, int], list[dict]] = {}
    for q in queries:
        groups.setdefault((q["from_sector"], q["to_sector"]), []).append(q)
    out: list[dict] = []
    lists = list(groups.values())
    for i in range(max((len(g) for g in lists), default=0)):
        out += [g[i] for g in lists if i < len(g)]
    return out if k is None else out[:k]


# --------------------------------------------------------------------------- one query, in a worker
_SEEDED: list[int] = []


def _seed_process(seed: int) -> None:
    from ompl import util as ou

    if not _SEEDED:  # a second setSeed in one process only prints an error
        ou.RNG.setSeed(int(seed))
        _SEEDED.append(int(seed))
    elif _SEEDED[0] != int(seed):
        log.warning("OMPL was seeded with %d in this process, not %d: runs are not reproducible", _SEEDED[0], seed)


def _sub_seed(*parts: int) -> int:
    return int(np.random.SeedSequence([int(p) for p in parts]).generate_state(1)[0])


def _experiment_specs(cfg: dict, qpos: int) -> list[dict]:
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


def _log_name(query: dict, qpos: int, spec: dict) -> str:
    tag = f"N{spec['cap']}" if spec["cap"] is not None else f"T{spec['budget']:g}s"
    return f"q{qpos:03d}_{spec['comparison']}_{spec['checker']}_{tag}.log"


def write_new_file(target: Path, text: str) -> bool:
    """Write ``text`` to ``target`` atomically and never over an existing file.

    The text goes to a unique ``.part`` file first, then is hard-linked to ``target`` (which fails
    if ``target`` exists, even when two processes race).  Returns False when ``target`` existed.
    """
    target = Path(target)
    tmp = target.with_name(f"{target.name}.{os.getpid()}.{time.monotonic_ns()}.part")
    with open(tmp, "w") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())
    try:
        os.link(tmp, target)
        return True
    except FileExistsError:
        return False
    finally:
        tmp.unlink()


def run_query_task(task: dict) -> dict:
    """Run the experiments of one query; return their OMPL logs as text plus per-run extras.

    ``task`` holds only plain data (OMPL objects cannot be pickled): ``config`` (dict of
    :class:`CampaignConfig`), ``query`` (dict), ``qpos`` (position in the set), ``query_set``,
    ``seed``, ``n_threads``, optionally ``specs`` (the experiments to run; default all) and
    ``log_dir``.  With ``log_dir`` each log is also written there as soon as its experiment ends
    (atomically, never over an existing file), so an interrupted campaign keeps it.

    Returns (JSON-able): ``qpos``, ``query_id``, ``logs`` ({file name: log text}), ``extras``
    ({file name: {planner: [per-run properties]}}), ``errors``, ``pid``, ``host``, ``elapsed``.
    """
    from ompl import util as ou

    from ..model.wearer_arm import WearerArm

    t0 = time.perf_counter()
    cfg, query, qpos = task["config"], task["query"], int(task["qpos"])
    _seed_process(task["seed"])
    ou.setLogLevel(ou.LOG_WARN)
    robot = WearerArm(n_threads=task.get("n_threads"))
    log_dir = Path(task["log_dir"]) if task.get("log_dir") else None
    specs = task.get("specs") or _experiment_specs(cfg, qpos)
    out: dict = {"qpos": qpos, "query_id": query["id"], "logs": {}, "extras": {}, "errors": {},
                 "pid": os.getpid(), "host": socket.gethostname()}
    for spec in specs:
        fname = _log_name(query, qpos, spec)
        text, extras, error = _run_experiment(robot, cfg, task, spec)
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
    from ompl import util as ou

    if before is not None and ou.getOutputHandler() is None:
        ou.restorePreviousOutputHandler()
        if ou.getOutputHandler() is None:
            ou.useOutputHandler(before)


def _failed_props(error: str) -> dict:
    return {"planner_error INTEGER": 1, "path_valid_dense INTEGER": 0, "reaches_goal INTEGER": 0,
            "error_message TEXT": error[:200].replace("\n", " ").replace(";", ",")}


def _run_experiment(robot, cfg: dict, task: dict, spec: dict) -> tuple[str, dict, str | None]:
    """One OMPL experiment; returns (log text, {planner: [run properties]}, benchmark error or None).

    Exceptions from Python callbacks never escape: planner exceptions are caught in
    :class:`RecordingPlanner`, event-callback exceptions in the events, and anything else that
    aborts ``benchmark()`` (e.g. a Python validity checker raising while OMPL checks the path)
    restores OMPL's logging and records every run that did not finish as a failed run
    (status *crash*, ``planner_error`` = 1).
    """
    from ompl import tools as ot
    from ompl import util as ou

    from ..planning.setup import make_simple_setup

    query, qpos = task["query"], int(task["qpos"])
    start, goal = np.asarray(query["start"], float), np.asarray(query["goal"], float)
    ss = make_simple_setup(robot, start, goal, batched_motion_validator=spec["checker"] == "batched")
    si = ss.getSpaceInformation()
    cap, budget = spec["cap"], spec["budget"]
    name = (f"{spec['comparison']}_{task['query_set']}_q{qpos:03d}_"
            + (f"N{cap}" if cap is not None else f"T{budget:g}s") + f"_{spec['checker']}")
    bench = ot.Benchmark(ss, name)
    params = {
        "comparison TEXT": spec["comparison"],
        "query_set TEXT": task["query_set"],
        "query_id TEXT": str(query["id"]),
        "query_index INTEGER": str(qpos),
        "from_sector INTEGER": str(query["from_sector"]),
        "to_sector INTEGER": str(query["to_sector"]),
        "sample_cap INTEGER": str(cap) if cap is not None else "0",
        "time_budget REAL": _fmt(budget) if budget is not None else "0",
        "motion_validator TEXT": spec["checker"],
        "straight_length REAL": _fmt(float(np.linalg.norm(goal - start))),
        "campaign_seed INTEGER": str(cfg["seed"]),
        "process_seed INTEGER": str(task["seed"]),
        "model_hash TEXT": robot.model_hash,
    }
    for k, v in params.items():
        pname, ptype = k.rsplit(" ", 1)
        bench.addExperimentParameter(pname, ptype, v)

    planners = cfg["iteration_planners"] if spec["comparison"] == "iterations" else cfg["anytime_planners"]
    wrappers = {}
    tag = cap if cap is not None else int(round(budget * 1000))
    for k, pname in enumerate(planners):
        ctx = PlannerContext(query=query, max_samples=cap, seed=_sub_seed(cfg["seed"], qpos, k, tag))
        inner = _factory(pname)(si, ctx)
        w = RecordingPlanner(si, inner, max_iterations=cap)
        wrappers[w.getName()] = w
        bench.addPlanner(w)

    records: dict[str, list[dict]] = {n: [] for n in wrappers}
    counter = {"before": 0}

    def pre_run(planner) -> None:
        counter["before"] = robot.collision_checks

    def post_run_props(planner) -> dict:
        checks = robot.collision_checks - counter["before"]
        w = wrappers[planner.getName()]
        rec = dict(w.last)
        W = rec.pop("waypoints", None)
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
        if W is not None and len(W) >= 1:
            l4, l12, l34 = group_lengths(W) if len(W) >= 2 else (0.0, 0.0, 0.0)
            ok = all(si.checkMotion(_state(si, W[i]), _state(si, W[i + 1])) for i in range(len(W) - 1))
            ok = ok and si.isValid(_state(si, W[0]))
            best = rec["best_cost"]
            if best is None or not math.isfinite(float(best)):
                best = l4
            ends = bool(np.allclose(W[0], start, atol=1e-6) and np.allclose(W[-1], goal, atol=1e-6))
            props.update({"reaches_goal INTEGER": int(ends), "best_cost REAL": best, "length_dof12 REAL": l12,
                          "length_dof34 REAL": l34, "raw_length REAL": l4, "path_valid_dense INTEGER": int(ok)})
        return {"props": props, "progress": rec["progress"]}

    def post_run(planner, run) -> None:
        try:
            rec = post_run_props(planner)
        except Exception as exc:  # noqa: BLE001 (would abort benchmark())
            log.exception("post-run event failed for %s", planner.getName())
            rec = {"props": _failed_props(repr(exc)), "progress": []}
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
        _pad_aborted_runs(bench, records, int(cfg["runs"]), error)
    _patch_recorded_data(bench, wrappers, records, cap)
    with tempfile.TemporaryDirectory(prefix="tpee_log_") as tmp:
        path = Path(tmp) / "experiment.log"
        bench.saveResultsToFile(str(path))
        text = path.read_text()
    extras = {n: [{k.rsplit(" ", 1)[0]: v for k, v in r["props"].items()} for r in recs] for n, recs in records.items()}
    return text, extras, error


def _guarded(fn: Callable, *args) -> None:
    try:
        fn(*args)
    except Exception:  # noqa: BLE001 (an exception would abort benchmark())
        log.exception("benchmark event %s failed", getattr(fn, "__name__", fn))


def _pad_aborted_runs(bench, records: dict, run_count: int, error: str) -> None:
    """After an aborted ``benchmark()``: add a failed run for every run that never finished."""
    from ompl import base as ob
    from ompl import tools as ot

    crash = str(ob.PlannerStatus.CRASH.value)
    for pl in bench.getRecordedExperimentData().planners:
        name = pl.name.split("_", 1)[1] if "_" in pl.name else pl.name
        recs = records.setdefault(name, [])
        runs = list(pl.runs)
        del recs[len(runs):]  # a record whose run was not stored (the abort came after the post-run event)
        while len(runs) < run_count:
            run = ot.RunProperties()
            for k, v in {"status ENUM": crash, "solved BOOLEAN": "0", "approximate solution BOOLEAN": "0",
                         "correct solution BOOLEAN": "0", "time REAL": "0", "memory REAL": "0"}.items():
                run[k] = v
            runs.append(run)
            recs.append({"props": _failed_props(error), "progress": []})
        pl.runs = runs


def _state(si, values):
    s = si.allocState()
    s[0 : len(values)] = [float(v) for v in values]
    return s


def _patch_recorded_data(bench, wrappers: dict, records: dict, cap: int | None) -> None:
    """Write the post-run records into the recorded experiment data (in place, before saving)."""
    for pl in bench.getRecordedExperimentData().planners:
        name = pl.name.split("_", 1)[1] if "_" in pl.name else pl.name
        recs = records.get(name, [])
        for run, rec in zip(pl.runs, recs):
            for k, v in rec["props"].items():
                run[k] = _fmt(v)
        w = wrappers[name]
        for k, v in _planner_settings(w.inner).items():
            pl.common[f"planner.{k}"] = v
        pl.common["iteration_cap"] = str(cap) if cap is not None else "none"
        pl.common["wrapper"] = "RecordingPlanner"
        pl.progressPropertyNames = list(PROGRESS_PROPERTIES)
        pl.runsProgressData = [
            [
                {"best cost REAL": _fmt(c), "iterations INTEGER": _fmt(n), "time REAL": _fmt(t)}
                for t, c, n in _dedupe_times(rec["progress"])
            ]
            for rec in recs
        ]


def _dedupe_times(progress: Sequence[tuple[float, float, int]]) -> list[tuple[float, float, int]]:
    """Keep the last entry per printed time (the progress table's key is (runid, time))."""
    out: dict[str, tuple[float, float, int]] = {}
    for t, c, n in progress:
        out[_fmt(float(t))] = (float(t), float(c), None if n is None else int(n))
    return sorted(out.values())


# --------------------------------------------------------------------------- campaign
def package_versions() -> dict[str, str]:
    """Versions of Python and the packages the results depend on."""
    from importlib import metadata

    out = {"python": platform.python_version(), "platform": platform.platform()}
    for dist in ("tpee_ompl", "ompl", "pin", "coal", "numpy", "matplotlib"):
        try:
            out[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            out[dist] = "not installed"
    return out


def make_results_dir(out: str | os.PathLike, name: str) -> Path:
    """A new ``<out>/<UTC timestamp>_<name>/`` folder; never an existing one."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    stamp = _dt.datetime.now(_dt.timezone.utc).strftime("%Y%m%dT%H%M%SZ")
    safe = "".join(c if c.isalnum() or c in "-_." else "_" for c in name)
    for k in range(1000):
        d = out / (f"{stamp}_{safe}" if k == 0 else f"{stamp}_{safe}_{k}")
        try:
            d.mkdir()
            return d
        except FileExistsError:
            continue
    raise RuntimeError(f"could not create a new results folder under {out}")


def new_output_stem(stem: str | os.PathLike, suffixes: Sequence[str] = (".csv", ".json")) -> Path:
    """``stem`` if none of ``stem + suffix`` exists, else ``<stem>_<UTC timestamp>[_k]``: results are never overwritten."""
    stem = Path(stem)
    stem.parent.mkdir(parents=True, exist_ok=True)
    if not any(stem.with_name(stem.name + s).exists() for s in suffixes):
        return stem
    stamp = _dt.datetime.now(_dt.timezone.utc).strftime("%Y%m%dT%H%M%SZ")
    for k in range(1000):
        cand = stem.with_name(f"{stem.name}_{stamp}" if k == 0 else f"{stem.name}_{stamp}_{k}")
        if not any(cand.with_name(cand.name + s).exists() for s in suffixes):
            return cand
    raise RuntimeError(f"no free output name for {stem}")


def build_database(logs: Sequence[os.PathLike], db_path: os.PathLike) -> tuple[Path | None, list[Path]]:
    """Build a Planner Arena SQLite database from OMPL ``.log`` files (ompl_benchmark_statistics).

    Each log is first parsed on its own (into an in-memory database); a log that fails is reported
    by name and skipped.  The database is written to ``<db>.part`` and renamed over ``db_path``
    only when complete, so an interruption never leaves a half-written database.  Returns the
    database (None when no log was readable) and the skipped logs.
    """
    from ompl import tools as ot

    db_path = Path(db_path)
    good, bad = [], []
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), _eof_guard(ot.readBenchmarkLog):  # it prints a line per file and planner
        for p in logs:
            try:
                if not Path(p).read_text().rstrip().endswith("\n."):  # every planner block ends with "."
                    raise ValueError("truncated (no final '.')")
                ot.readBenchmarkLog(":memory:", [str(p)], False)
                good.append(Path(p))
            except Exception as exc:  # noqa: BLE001 (any parse error: the file is corrupt)
                log.error("skipping corrupt log %s: %r", Path(p).name, exc)
                bad.append(Path(p))
    if not good:
        return None, bad
    tmp = db_path.with_name(db_path.name + ".part")
    tmp.unlink(missing_ok=True)
    try:
        with contextlib.redirect_stdout(buf):
            ot.readBenchmarkLog(str(tmp), [str(p) for p in good], False)
            ot.computeViews(str(tmp), False)
        os.replace(tmp, db_path)
    finally:
        tmp.unlink(missing_ok=True)
    return db_path, bad


class _EofGuardedFile:
    """A text file whose ``readline`` raises after many reads at end of file.

    OMPL's ``readBenchmarkLog`` loops forever on some truncated logs (it keeps reading ``''``).
    """

    def __init__(self, f, limit: int = 1000) -> None:
        self._f, self._limit, self._eof_reads = f, limit, 0

    def readline(self, *args) -> str:
        line = self._f.readline(*args)
        if line == "":
            self._eof_reads += 1
            if self._eof_reads > self._limit:
                raise ValueError(f"unexpected end of file in {self._f.name}")
        return line

    def __getattr__(self, name: str):
        return getattr(self._f, name)

    def __iter__(self):
        return iter(self._f)


@contextlib.contextmanager
def _eof_guard(reader: Callable):
    """Within the block, files opened by ``reader``'s module are :class:`_EofGuardedFile`."""
    import builtins

    mod = sys.modules[reader.__module__]
    had = "open" in vars(mod)
    previous = vars(mod).get("open")
    mod.open = lambda *a, **k: _EofGuardedFile(builtins.open(*a, **k))
    try:
        yield
    finally:
        if had:
            mod.open = previous
        else:
            del mod.open


def _write_json(path: Path, data: dict) -> None:
    tmp = path.with_name(path.name + ".part")
    tmp.write_text(json.dumps(data, indent=2))
    os.replace(tmp, path)


@contextlib.contextmanager
def _sigterm_as_keyboard_interrupt():
    """Within the block, SIGTERM interrupts like Ctrl-C (main thread only)."""
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum, frame):
        raise KeyboardInterrupt(f"signal {signum}")

    previous = signal.signal(signal.SIGTERM, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def run_campaign(
    config: CampaignConfig,
    *,
    on_task_done: Callable[[list[str]], None] | None = None,
    report: bool = True,
    progress_bar: bool = True,
    executor=None,
) -> CampaignResult:
    """Run a campaign into a new timestamped folder, build the DB, the report and the plots.

    ``executor`` (:mod:`tpee_ompl.bench.executors`) runs the per-query tasks; default: a local spawn
    pool of ``config.workers`` processes (0 = this process).  ``on_task_done`` is called in this
    process with each finished query's log paths.  Ctrl-C or SIGTERM (or a KeyboardInterrupt from
    ``on_task_done``) stops the campaign: finished logs are kept, the database is still built from
    them, and :func:`resume_campaign` runs the rest later.
    """
    with _sigterm_as_keyboard_interrupt():
        return _run_campaign(config, on_task_done, report, progress_bar, executor)


def _run_campaign(config: CampaignConfig, on_task_done, report: bool, progress_bar: bool, executor) -> CampaignResult:
    set_name, queries = load_query_set(config.queries)
    queries = stratified_subset(queries, config.max_queries)
    if not queries:
        raise ValueError(f"query set {config.queries!r} has no queries")
    directory = make_results_dir(config.out, config.name)
    (directory / "logs").mkdir()
    cfg = dataclasses.asdict(config)
    meta = {
        "config": cfg,
        "query_set": set_name,
        "queries": [q["id"] for q in queries],
        "query_data": queries,
        "expected_experiments": sum(len(_experiment_specs(cfg, k)) for k in range(len(queries))),
        "seed": config.seed,
        "process_seeds": {str(q["id"]): config.seed + k for k, q in enumerate(queries)},
        "versions": package_versions(),
        "hostname": socket.gethostname(),
        "cpu_count": os.cpu_count(),
        "command": sys.argv,
        "started_utc": _dt.datetime.now(_dt.timezone.utc).isoformat(),
        "interrupted": True,  # until the campaign ends (a killed campaign stays marked)
    }
    _write_json(directory / "campaign.json", meta)
    return _execute(directory, meta, executor, on_task_done, report, progress_bar)


def resume_campaign(
    directory: str | os.PathLike,
    *,
    executor=None,
    workers: int | None = None,
    on_task_done: Callable[[list[str]], None] | None = None,
    report: bool = True,
    progress_bar: bool = True,
) -> CampaignResult:
    """Run only the experiments of an interrupted campaign that have no log yet, into its folder.

    Finished logs are never touched; the database and report are rebuilt from all logs.  The
    configuration and queries come from the folder's ``campaign.json``; ``workers`` overrides the
    pool size.  A query resumed part-way runs its missing experiments in a fresh process seeded
    as before, so they are valid runs but (OMPL's RNG stream being shared by the experiments of a
    query) not bit-identical to an uninterrupted campaign.
    """
    directory = Path(directory)
    meta = json.loads((directory / "campaign.json").read_text())
    if "query_data" not in meta:
        raise ValueError(f"{directory} was written by an older version (no query_data): cannot resume")
    if workers is not None:
        meta["config"]["workers"] = int(workers)
    meta.setdefault("resumed_utc", []).append(_dt.datetime.now(_dt.timezone.utc).isoformat())
    (directory / "logs").mkdir(exist_ok=True)
    return _execute(directory, meta, executor, on_task_done, report, progress_bar)


def _execute(directory: Path, meta: dict, executor, on_task_done, report: bool, progress_bar: bool) -> CampaignResult:
    cfg = meta["config"]
    log_dir = directory / "logs"
    interrupted = False
    t0 = time.perf_counter()
    with _sigterm_as_keyboard_interrupt():
        try:
            from tqdm import tqdm

            from .executors import make_executor, run_task_in_subprocess

            for part in log_dir.glob("*.part"):  # left by a process killed while writing
                part.unlink()
            done_names = {p.name for p in log_dir.glob("*.log")}
            executor = executor if executor is not None else make_executor(int(cfg["workers"]))
            in_process = not getattr(executor, "fresh_process_per_task", True)
            shared_fs = getattr(executor, "shares_filesystem", True)
            n_threads = None if in_process or int(cfg["workers"]) == 1 and shared_fs else 1
            tasks = []
            for k, q in enumerate(meta["query_data"]):
                specs = [s for s in _experiment_specs(cfg, k) if _log_name(q, k, s) not in done_names]
                if specs:
                    tasks.append({"config": cfg, "query": q, "qpos": k, "query_set": meta["query_set"],
                                  "seed": cfg["seed"] + k, "specs": specs, "n_threads": n_threads,
                                  "log_dir": str(log_dir) if shared_fs else None,
                                  "sys_path": [p for p in sys.path if p]})
            fn = run_query_task if shared_fs else run_task_in_subprocess
            meta["executor"] = executor.description
            log.info("campaign %s: %d queries, %d experiments (%d to run) on %s", directory, len(meta["query_data"]),
                     meta["expected_experiments"], sum(len(t["specs"]) for t in tasks), executor.description)
            with tqdm(total=len(tasks), desc=f"{cfg['name']} queries", unit="query", disable=not progress_bar) as bar:
                for res in executor.run(fn, tasks):
                    written = _store_task_result(directory, res)
                    bar.update(1)
                    if on_task_done:
                        on_task_done(written)
            executor.shutdown()
        except KeyboardInterrupt:
            interrupted = True
            log.warning("interrupted: building the database from the finished logs")
        finally:
            if executor is not None:
                executor.shutdown(cancel=True)
        for part in log_dir.glob("*.part"):
            part.unlink()
        logs = sorted(log_dir.glob("*.log"))
        meta.update({"finished_utc": _dt.datetime.now(_dt.timezone.utc).isoformat(), "interrupted": interrupted,
                     "finished_experiments": len(logs), "wall_time_s": time.perf_counter() - t0})
        result = CampaignResult(directory=directory, logs=logs, database=None, interrupted=interrupted)
        if logs:
            result.database, result.skipped_logs = build_database(logs, directory / "benchmark.db")
            meta["corrupt_logs"] = [p.name for p in result.skipped_logs]
        _write_json(directory / "campaign.json", meta)
        if result.database is not None and report:
            from . import plots
            from . import report as rep

            result.report = rep.write_report(result.database, directory, expected=meta)
            result.plots = plots.make_plots(result.database, directory / "plots")
    return result


def _store_task_result(directory: Path, res: dict) -> list[str]:
    """Write a task's logs into the campaign folder (never over a different existing log)."""
    log_dir = directory / "logs"
    written = []
    for fname, text in res["logs"].items():
        target = log_dir / Path(fname).name
        if not write_new_file(target, text) and target.read_text() != text:
            log.warning("%s exists with other content: kept the existing log", target.name)
        written.append(str(target))
    line = {k: res.get(k) for k in ("qpos", "query_id", "pid", "host", "elapsed", "errors")}
    line["logs"] = sorted(res["logs"])
    with open(directory / "tasks.jsonl", "a") as f:
        f.write(json.dumps(line) + "\n")
    return written


# --------------------------------------------------------------------------- command line
def build_parser(prog: str | None = None) -> argparse.ArgumentParser:
    """Arguments of ``experiments/run_benchmark.py`` and ``tpee-ompl bench``."""
    p = argparse.ArgumentParser(prog=prog, description="Benchmark dimension-RRT against OMPL planners (ompl.tools.Benchmark).")
    p.add_argument("--queries", default="planning_necessary", help="query-set name or JSON file (default: %(default)s)")
    p.add_argument("--name", default=None, help="results folder suffix (default: the query-set name)")
    p.add_argument("--samples", type=int, nargs="*", default=[500, 1000, 1500, 2000, 2500],
                   help="sample/iteration caps of the Table-4 comparison (default: %(default)s); none to skip")
    p.add_argument("--anytime", type=float, nargs="*", default=[0.1, 0.5, 1.0, 2.0],
                   help="time budgets (s) of the anytime comparison (default: %(default)s); none to skip")
    p.add_argument("--planners", nargs="+", default=list(ITERATION_PLANNERS),
                   help="iteration-matched planners; the first is compared with the second (default: %(default)s)")
    p.add_argument("--anytime-planners", nargs="+", default=list(ANYTIME_PLANNERS), help="(default: %(default)s)")
    p.add_argument("--checkers", nargs="+", default=["batched", "discrete"], choices=CHECKERS,
                   help="motion validators; the first is the headline (default: %(default)s)")
    p.add_argument("--alt-checker-queries", type=int, default=None,
                   help="run the non-headline validators on the first k queries only (default: all)")
    p.add_argument("--alt-checker-samples", type=int, nargs="+", default=None,
                   help="caps for the non-headline validators (default: all --samples)")
    p.add_argument("--anytime-queries", type=int, default=None, help="anytime comparison on the first k queries only")
    p.add_argument("--max-queries", type=int, default=None, help="use N queries, round-robin over the ordered sector pairs")
    p.add_argument("--runs", type=int, default=1, help="runs per planner per experiment (default: %(default)s)")
    p.add_argument("--workers", type=int, default=max(1, min(2, os.cpu_count() or 1)),
                   help="worker processes, one fresh process per query; 0 = in this process (default: %(default)s)")
    p.add_argument("--seed", type=int, default=1, help="campaign seed; query k's process uses seed + k (default: %(default)s)")
    p.add_argument("--max-time", type=float, default=300.0, help="safety limit per iteration-capped run, s")
    p.add_argument("--out", default="results", help="parent folder of the timestamped results folder")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    g = p.add_argument_group("executor (default: local process pool of --workers)")
    g.add_argument("--dask", metavar="local|tcp://HOST:PORT", default=None,
                   help="run the queries as Dask tasks: 'local' starts a LocalCluster here, an address uses that "
                        "scheduler (needs the dask extra: pip install 'tpee_ompl[dask]')")
    g.add_argument("--scheduler", metavar="tcp://HOST:PORT", default=None, help="same as --dask tcp://HOST:PORT")
    g.add_argument("--dask-workers", type=int, default=2, help="workers of --dask local (default: %(default)s)")
    g.add_argument("--retries", type=int, default=2, help="Dask retries of a task that raises (default: %(default)s)")
    p.add_argument("--resume", metavar="DIR", default=None,
                   help="finish an interrupted campaign in DIR: run only its missing experiments (configuration "
                        "from DIR/campaign.json; the other campaign options are ignored)")
    return p


def config_from_args(args: argparse.Namespace) -> CampaignConfig:
    """A :class:`CampaignConfig` from parsed arguments."""
    name = args.name or Path(args.queries).stem
    return CampaignConfig(
        name=name,
        queries=args.queries,
        sample_caps=tuple(args.samples or ()),
        iteration_planners=tuple(args.planners),
        checkers=tuple(args.checkers),
        alt_checker_queries=args.alt_checker_queries,
        alt_checker_caps=tuple(args.alt_checker_samples) if args.alt_checker_samples else None,
        anytime_budgets=tuple(args.anytime or ()),
        anytime_planners=tuple(args.anytime_planners),
        anytime_queries=args.anytime_queries,
        max_queries=args.max_queries,
        runs=args.runs,
        workers=args.workers,
        seed=args.seed,
        out=args.out,
        max_time=args.max_time,
    )


def main(argv: Sequence[str] | None = None) -> int:
    """Run a campaign from the command line; print the ratio table and where the files are."""
    args = build_parser().parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    from .executors import make_executor

    try:
        config = config_from_args(args)
        if args.resume and not (Path(args.resume) / "campaign.json").is_file():
            raise ValueError(f"--resume {args.resume}: no campaign.json there")
        executor = make_executor(config.workers, dask=args.scheduler or args.dask, dask_workers=args.dask_workers,
                                 retries=args.retries)
    except (ValueError, ImportError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    try:
        if args.resume:
            result = resume_campaign(args.resume, executor=executor, workers=config.workers,
                                     progress_bar=not args.no_progress)
        else:
            result = run_campaign(config, executor=executor, progress_bar=not args.no_progress)
    except KeyboardInterrupt:  # a second Ctrl-C while the database was built
        print("interrupted; finished logs are kept: finish the campaign with --resume DIR", file=sys.stderr)
        return 130
    if result.report.get("markdown_text"):
        print(result.report["markdown_text"])
    print(f"results: {result.directory}")
    print(f"database: {result.database}  (open in Planner Arena: plannerarena.org)")
    if result.report:
        print(f"report: {result.report.get('markdown')}  {result.report.get('csv')}")
    if result.plots:
        print(f"plots: {result.directory / 'plots'} ({len(result.plots)} PNG)")
    if result.skipped_logs:
        print(f"skipped {len(result.skipped_logs)} corrupt log(s): " + ", ".join(p.name for p in result.skipped_logs))
    if result.interrupted:
        print("campaign was interrupted: the database holds the finished experiments only; "
              f"finish it with --resume {result.directory}")
        return 130
    return 0
