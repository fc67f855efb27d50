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
import multiprocessing as mp
import os
import platform
import signal
import socket
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

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
    "run_query_task",
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
QUERY_DIR = REPO_ROOT / "experiments" / "queries"


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
    from .dimension_rrt import tpee_dimension_rrt

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
            self.inner.setProblemDefinition(self.getProblemDefinition())
            self.inner.setup()

        def clear(self) -> None:  # noqa: D102 (OMPL override)
            super().clear()
            self.inner.clear()

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

            error = None
            try:
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
        from .queries import load_queries  # written in parallel; fall back to the JSON format
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


def run_query_task(task: dict) -> list[str]:
    """Run every experiment of one query and write one ``.log`` per experiment; return their paths.

    ``task`` holds only plain data (OMPL objects cannot be pickled): ``config`` (dict of
    :class:`CampaignConfig`), ``query`` (dict), ``qpos`` (position in the set), ``query_set``,
    ``seed``, ``log_dir``, ``n_threads``.  Logs are written to a temporary name and renamed when
    complete, so an interrupted campaign never leaves a partial log.
    """
    from ompl import util as ou

    from .robot import WearerArm

    cfg, query, qpos = task["config"], task["query"], int(task["qpos"])
    _seed_process(task["seed"])
    ou.setLogLevel(ou.LOG_WARN)
    robot = WearerArm(n_threads=task.get("n_threads"))
    log_dir = Path(task["log_dir"])
    written = []
    for spec in _experiment_specs(cfg, qpos):
        target = log_dir / _log_name(query, qpos, spec)
        _run_experiment(robot, cfg, task, spec, target)
        written.append(str(target))
    return written


def _run_experiment(robot, cfg: dict, task: dict, spec: dict, target: Path) -> None:
    from ompl import tools as ot
    from ompl import util as ou

    from .ompl_problem import make_simple_setup

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

    def post_run(planner, run) -> None:
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
            props.update({"reaches_goal INTEGER": int(ends), "best_cost REAL": best, "length_dof12 REAL": l12, "length_dof34 REAL": l34,
                          "raw_length REAL": l4, "path_valid_dense INTEGER": int(ok)})
        records[planner.getName()].append({"props": props, "progress": rec["progress"]})

    bench.setPreRunEvent(pre_run)
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
    try:
        bench.benchmark(req)
    finally:
        ou.restorePreviousOutputHandler()
        ou.setLogLevel(ou.LOG_WARN)
    _patch_recorded_data(bench, wrappers, records, cap)
    tmp = target.with_suffix(".log.part")
    bench.saveResultsToFile(str(tmp))
    os.replace(tmp, target)


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


def build_database(logs: Sequence[os.PathLike], db_path: os.PathLike) -> Path:
    """Build a Planner Arena SQLite database from OMPL ``.log`` files (ompl_benchmark_statistics)."""
    from ompl import tools as ot

    db_path = Path(db_path)
    if db_path.exists():
        db_path.unlink()
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):  # readBenchmarkLog prints one line per file and planner
        ot.readBenchmarkLog(str(db_path), [str(p) for p in logs], False)
        ot.computeViews(str(db_path), False)
    return db_path


def _ignore_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _pool_run(task: dict) -> list[str]:
    return run_query_task(task)


def run_campaign(
    config: CampaignConfig,
    *,
    on_task_done: Callable[[list[str]], None] | None = None,
    report: bool = True,
    progress_bar: bool = True,
) -> CampaignResult:
    """Run a campaign into a new timestamped folder, build the DB, the report and the plots.

    ``on_task_done`` is called in this process with each finished query's log paths.  Ctrl-C (or
    a KeyboardInterrupt from ``on_task_done``) stops the campaign: finished logs are kept and the
    database is still built from them.
    """
    from tqdm import tqdm

    set_name, queries = load_query_set(config.queries)
    queries = stratified_subset(queries, config.max_queries)
    if not queries:
        raise ValueError(f"query set {config.queries!r} has no queries")
    directory = make_results_dir(config.out, config.name)
    log_dir = directory / "logs"
    log_dir.mkdir()
    cfg = dataclasses.asdict(config)
    n_threads = 1 if config.workers > 1 else None
    tasks = [
        {"config": cfg, "query": q, "qpos": k, "query_set": set_name, "seed": config.seed + k,
         "log_dir": str(log_dir), "n_threads": n_threads}
        for k, q in enumerate(queries)
    ]
    meta = {
        "config": cfg,
        "query_set": set_name,
        "queries": [q["id"] for q in queries],
        "expected_experiments": sum(len(_experiment_specs(cfg, k)) for k in range(len(queries))),
        "seed": config.seed,
        "process_seeds": {str(q["id"]): t["seed"] for q, t in zip(queries, tasks)},
        "versions": package_versions(),
        "hostname": socket.gethostname(),
        "cpu_count": os.cpu_count(),
        "command": sys.argv,
        "started_utc": _dt.datetime.now(_dt.timezone.utc).isoformat(),
    }
    (directory / "campaign.json").write_text(json.dumps(meta, indent=2))
    log.info("campaign %s: %d queries, %d experiments", directory, len(queries), meta["expected_experiments"])

    interrupted = False
    bar = tqdm(total=len(tasks), desc=f"{config.name} queries", unit="query", disable=not progress_bar)
    pool = None
    try:
        if config.workers == 0:
            for t in tasks:
                done = run_query_task(t)
                bar.update(1)
                if on_task_done:
                    on_task_done(done)
        else:
            ctx = mp.get_context("spawn")
            pool = ctx.Pool(processes=config.workers, maxtasksperchild=1, initializer=_ignore_sigint)
            for done in pool.imap_unordered(_pool_run, tasks):
                bar.update(1)
                if on_task_done:
                    on_task_done(done)
            pool.close()
            pool.join()
    except KeyboardInterrupt:
        interrupted = True
        log.warning("interrupted: building the database from the finished logs")
        if pool is not None:
            pool.terminate()
            pool.join()
    finally:
        bar.close()
    for part in log_dir.glob("*.part"):
        part.unlink()
    logs = sorted(log_dir.glob("*.log"))
    meta.update({"finished_utc": _dt.datetime.now(_dt.timezone.utc).isoformat(), "interrupted": interrupted,
                 "finished_experiments": len(logs)})
    (directory / "campaign.json").write_text(json.dumps(meta, indent=2))
    result = CampaignResult(directory=directory, logs=logs, database=None, interrupted=interrupted)
    if logs:
        result.database = build_database(logs, directory / "benchmark.db")
        if report:
            from . import plots
            from . import report as rep

            result.report = rep.write_report(result.database, directory, expected=meta)
            result.plots = plots.make_plots(result.database, directory / "plots")
    return result


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
    try:
        config = config_from_args(args)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    result = run_campaign(config, progress_bar=not args.no_progress)
    if result.report.get("markdown_text"):
        print(result.report["markdown_text"])
    print(f"results: {result.directory}")
    print(f"database: {result.database}  (open in Planner Arena: plannerarena.org)")
    if result.report:
        print(f"report: {result.report.get('markdown')}  {result.report.get('csv')}")
    if result.plots:
        print(f"plots: {result.directory / 'plots'} ({len(result.plots)} PNG)")
    if result.interrupted:
        print("campaign was interrupted: the database holds the finished experiments only")
        return 130
    return 0
