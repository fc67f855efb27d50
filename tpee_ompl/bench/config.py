"""What a benchmark campaign runs (:class:`CampaignConfig`), where it wrote (:class:`CampaignResult`),
a campaign folder's saved configuration read back for a resume (:func:`load_campaign`), and the names the
campaign knows: planners, motion validators, progress columns.

Imports no OMPL: the command-line parser (``tpee-ompl --help``) is built from this module alone.
The command line takes its defaults from :class:`CampaignConfig`'s fields (one source).
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

from ..validation import MOTION_VALIDATORS

__all__ = [
    "ANYTIME_PLANNERS",
    "CHECKERS",
    "DEFAULT_CHECKERS",
    "CLI_PLANNER_NAMES",
    "CampaignConfig",
    "CampaignResult",
    "ITERATION_PLANNERS",
    "KNOWN_PLANNERS",
    "PROGRESS_PROPERTIES",
    "check_planner_name",
    "default_workers",
    "load_campaign",
]

ITERATION_PLANNERS = ("DimensionRRT", "RRTstar")
"""Planners of the iteration-matched (Table 4) comparison: dimension-RRT first, the reference second."""
CLI_PLANNER_NAMES: dict[str, str] = {
    "dimension-rrt": "DimensionRRT",
    "library": "LibraryDimensionRRT",
    "rrtstar": "RRTstar",
    "informedrrtstar": "InformedRRTstar",
    "rrtconnect": "RRTConnect",
    "rrtconnect-simplify": "RRTConnectSimplify",
    "aorrtc": "AORRTC",
    "bitstar": "BITstar",
}
"""``tpee-ompl plan --planner`` name -> benchmark planner name (= OMPL class name, but for this package's
DimensionRRT, LibraryDimensionRRT (the DMP library refined by dimension-RRT) and RRTConnectSimplify
(RRTConnect followed by OMPL's PathSimplifier, its simplification in its time)).
The planners of :data:`ANYTIME_PLANNERS`, in the same order."""
ANYTIME_PLANNERS: tuple[str, ...] = tuple(CLI_PLANNER_NAMES.values())
"""Planners of the time-matched comparison (every planner the command line knows)."""
KNOWN_PLANNERS: tuple[str, ...] = (*ANYTIME_PLANNERS, "DimensionRRTReleased", "DimensionRRTNoShortcuts", "RRT")
"""Every built-in planner name (:data:`tpee_ompl.bench.planners.PLANNER_FACTORIES`); ``module:function`` names a factory elsewhere.
``DimensionRRTReleased`` (named on demand, not in a default comparison) is dimension-RRT with
``release_after=RELEASE_AFTER``: prescribed rows planned too once the path converged on them;
``DimensionRRTNoShortcuts`` (also on demand) improves by the paper's rule alone (``shortcuts=False``).
PRM* is not among them: its solve asks the termination condition from a thread of its own while the calling
thread waits for it holding Python's lock, so with the benchmark's Python condition it deadlocked at random
(and ignored SIGTERM); ``module:function`` can still name a factory for it."""
OUR_PLANNER_NOTES: dict[str, str] = {
    "DimensionRRT": "the paper's dimension-RRT with shortcut sweeps between fake-time waypoints after each "
                    "improvement (the paper's rule alone: DimensionRRTNoShortcuts)",
    "DimensionRRTNoShortcuts": "the paper's dimension-RRT, improved by the paper's rule alone",
    "DimensionRRTReleased": "DimensionRRT whose rows are planned too once its path converged on them",
    "LibraryDimensionRRT": "the DMP path library's validated path, refined by dimension-RRT (rows released)",
    "RRTConnectSimplify": "OMPL's RRTConnect, then OMPL's PathSimplifier in the time left",
}
"""What this package's benchmark planners are, one line each (a report says it beside their names)."""
WEARER_PLANNER_NOTES: dict[str, str] = {
    "DimensionRRT": "on the wearer Table 3's DOF1/DOF2 rows are kept",
    "DimensionRRTNoShortcuts": "on the wearer Table 3's DOF1/DOF2 rows are kept",
}
"""What a report adds to :data:`OUR_PLANNER_NOTES` for the wearer's cross-sector queries."""
NOT_ITERATION_CAPPED: tuple[str, ...] = ("RRTConnect", "RRTConnectSimplify", "AORRTC", "RRT")
"""Planners that cannot be stopped at a sample count (their ompl 2.0.1 bindings have no ``numIterations()``), so they
never join the iteration-matched comparison; refused there before a campaign starts."""
MAX_NAME_BYTES = 234
"""Longest campaign name: ``<UTC time>_<name>`` (and a ``_999`` that tells two campaigns of one second apart) must
fit a file name, 255 bytes on most file systems."""
CHECKERS = MOTION_VALIDATORS
"""A campaign's motion validators (:data:`~tpee_ompl.validation.MOTION_VALIDATORS`); ``certified`` and ``dense``
on robot-checker problems only."""
DEFAULT_CHECKERS = ("batched", "discrete")
"""The validators a campaign runs unless told (``certified`` is chosen explicitly: ``--checkers``)."""
PROGRESS_PROPERTIES = ["best cost REAL", "iterations INTEGER", "time REAL"]  # sorted, as OMPL's map
"""Columns of the ``progress`` table (name and SQL type, as OMPL's log writes them)."""


def check_planner_name(name: object, what: str = "planner") -> str:
    """``name`` if it is a built-in planner (:data:`KNOWN_PLANNERS`) or a ``module:function`` factory name.

    Whether ``module:function`` imports is checked before a campaign starts
    (:func:`tpee_ompl.bench.campaign.prepare_campaign`).
    """
    if isinstance(name, str) and name in KNOWN_PLANNERS:
        return name
    if isinstance(name, str) and ":" in name:
        mod, _, attr = name.partition(":")
        if mod and attr.isidentifier() and all(part.isidentifier() for part in mod.split(".")):
            return name
    raise ValueError(f"unknown {what} {name!r}: choose from {', '.join(KNOWN_PLANNERS)} or give module:function")


def default_workers() -> int:
    """Default worker processes: two, or one on a single-core machine."""
    return max(1, min(2, os.cpu_count() or 1))


@dataclass(frozen=True)
class CampaignConfig:
    """What one campaign runs.  Times in seconds, caps in samples (= RRT* iterations)."""

    name: str = "bench"
    """Folder suffix: ``<out>/<UTC timestamp>_<name>/``."""
    problem: str = "wearer"
    """Benchmark problem (:data:`tpee_ompl.bench.problems.PROBLEM_NAMES`): the wearer, its random queries,
    generic OMPL problems, robot-checker problems."""
    queries: str | None = None
    """Query-set name (packaged ``data/queries/<name>.json``) or a JSON file path, for the problems that read
    query sets; None = the problem's own queries (the wearer's: ``planning_necessary``)."""
    sample_caps: tuple[int, ...] = (500, 1000, 1500, 2000, 2500)
    iteration_planners: tuple[str, ...] = ITERATION_PLANNERS
    checkers: tuple[str, ...] = DEFAULT_CHECKERS
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
    """Use k queries, round-robin over sector pairs (:func:`~tpee_ompl.bench.campaign.stratified_subset`; None = all)."""
    runs: int = 1
    """Runs per planner per experiment."""
    workers: int = field(default_factory=default_workers)
    """Worker processes (one fresh process per query); 0 runs in this process (tests)."""
    seed: int = 1
    """Campaign seed; query k's process seeds OMPL with ``seed + k``."""
    out: str = "results"
    max_time: float = 300.0
    """Safety time limit per iteration-capped run (s); a run hitting it counts as a failure."""
    simplify: bool = True
    """OMPL's default; ``solution_length`` stays the raw length either way."""
    one_run_per_ladder: bool = True
    """Run each iteration ladder (every cap of one validator) once, at its largest cap, and read the smaller
    caps' rows at checkpoints (:mod:`tpee_ompl.bench.ladder`); False: one separate run per cap."""
    one_run_per_anytime_ladder: bool = True
    """Run each anytime ladder (every budget of one validator) once, at its longest budget, and read the shorter
    budgets' rows at time checkpoints where that is exact (:mod:`tpee_ompl.bench.anytime_ladder`; the other
    planners run separately per budget); False: one separate run per budget."""

    @classmethod
    def for_problem(cls, problem: str, **fields) -> CampaignConfig:
        """A configuration for ``problem`` whose motion validators and anytime planners default to the problem's."""
        from .problems import get_problem

        p = get_problem(problem)
        fields.setdefault("checkers", tuple(c for c in p.checkers if c in DEFAULT_CHECKERS))
        fields.setdefault("anytime_planners", p.planners)
        return cls(problem=problem, **fields)

    def __post_init__(self) -> None:
        from ..validation import MAX_COUNT, MAX_SECONDS, check_bool, check_int, check_name, check_number, check_seed

        from .problems import get_problem

        check_name("name", self.name)
        if len(self.name.encode()) > MAX_NAME_BYTES:  # it is part of the results folder's name
            raise ValueError(f"name must be at most {MAX_NAME_BYTES} bytes (it names the results folder; without "
                             f"--name, the query set's file name does), got {len(self.name.encode())}")
        problem = get_problem(self.problem)
        if self.queries is not None:
            check_name("queries", self.queries)
            if not problem.query_sets:
                raise ValueError(f"queries: problem {self.problem} has built-in queries (give no query set)")
        check_name("out", self.out)
        set_ = lambda field_, value: object.__setattr__(self, field_, value)  # noqa: E731 (frozen dataclass)
        # plain ints and floats (numpy scalars passed the checks, then failed as JSON once the folder existed)
        caps = tuple(check_int("sample_caps", n, minimum=1, maximum=MAX_COUNT) for n in self.sample_caps)
        budgets = tuple(check_number("anytime_budgets", b, low=0, low_open=True, high=MAX_SECONDS) for b in self.anytime_budgets)
        set_("sample_caps", caps)
        set_("anytime_budgets", budgets)
        for field_name, values, text in (("sample_caps", caps, str), ("anytime_budgets", budgets, lambda b: f"{b:g}")):
            if len({text(v) for v in values}) != len(values):  # one log name per value: a second would be dropped
                raise ValueError(f"{field_name} names a value twice (as the logs name it): {list(values)}")
        if not caps and not budgets:
            raise ValueError("nothing to run: sample_caps and anytime_budgets are both empty")
        if not caps and self.anytime_queries == 0:
            raise ValueError("nothing to run: no sample_caps, and anytime_queries is 0")
        for field_name, names in (("iteration_planners", self.iteration_planners),
                                  ("anytime_planners", self.anytime_planners)):
            for n in names:
                check_planner_name(n, f"{field_name} entry")
            if len(set(names)) != len(names):
                raise ValueError(f"{field_name} names a planner twice: {list(names)}")
            for n in names:
                try:
                    problem.check_planner(n)
                except ValueError as exc:
                    raise ValueError(f"{field_name}: {exc}") from None
        for n in self.iteration_planners:
            if n in NOT_ITERATION_CAPPED:
                raise ValueError(f"iteration_planners: {n} cannot be stopped at a sample count (it counts no "
                                 "iterations); compare it in the anytime comparison")
        if caps and not self.iteration_planners:
            raise ValueError("iteration_planners: give at least one planner for the sample caps")
        if budgets and not self.anytime_planners:
            raise ValueError("anytime_planners: give at least one planner for the anytime budgets")
        if len(set(self.checkers)) != len(self.checkers):
            raise ValueError(f"checkers names a motion validator twice: {list(self.checkers)}")
        for c in self.checkers:
            if c not in CHECKERS:
                raise ValueError(f"unknown motion validator {c!r}: choose from {CHECKERS}")
            if c not in problem.checkers:
                raise ValueError(f"checkers: problem {self.problem} has no {c!r} motion validator (it has "
                                 f"{', '.join(problem.checkers)})")
        if caps and not self.checkers:
            raise ValueError("give at least one motion validator")
        set_("alt_checker_queries", check_int("alt_checker_queries", self.alt_checker_queries, minimum=0, optional=True))
        if self.alt_checker_caps is not None:
            if not self.alt_checker_caps:
                raise ValueError("alt_checker_caps must be None or at least one cap")
            set_("alt_checker_caps", tuple(check_int("alt_checker_caps", n, minimum=1, maximum=MAX_COUNT)
                                           for n in self.alt_checker_caps))
        # counts capped as the command line caps them (a campaign.json edited to runs: 10**9 resumed for ever)
        set_("anytime_queries", check_int("anytime_queries", self.anytime_queries, minimum=0, maximum=MAX_COUNT,
                                          optional=True))
        set_("max_queries", check_int("max_queries", self.max_queries, minimum=1, maximum=MAX_COUNT, optional=True))
        set_("runs", check_int("runs", self.runs, minimum=1, maximum=MAX_COUNT))
        set_("workers", check_int("workers", self.workers, minimum=0, maximum=MAX_COUNT))
        set_("seed", check_seed("seed", self.seed))
        set_("max_time", check_number("max_time", self.max_time, low=0, low_open=True, high=MAX_SECONDS))
        for flag in ("simplify", "one_run_per_ladder", "one_run_per_anytime_ladder"):
            set_(flag, check_bool(flag, getattr(self, flag)))


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
    failed_tasks: list[dict] = field(default_factory=list)
    """Queries whose worker died twice (or raised): ``qpos``, ``query_id``, ``reason``, ``attempts``, ``missing_logs``."""
    broken_logs: list[Path] = field(default_factory=list)
    """Logs found unreadable at resume, moved to ``logs/broken/`` and run again."""
    plots: list[Path] = field(default_factory=list)


def load_campaign(directory: str | os.PathLike) -> dict:
    """The ``campaign.json`` of a campaign folder, checked for resuming; ValueError naming what is wrong."""
    directory = Path(directory)
    if not directory.is_dir():
        raise ValueError(f"resume {directory}: not a folder")
    path = directory / "campaign.json"
    if not path.is_file():
        raise ValueError(f"resume {directory}: not a campaign folder (no campaign.json there)")
    for name, folder in (("logs", True), ("tasks.jsonl", False), (".lock", False), ("plots", True)):
        if (directory / name).exists() and (directory / name).is_dir() != folder:  # the OS would say "File exists"
            raise ValueError(f"resume {directory}: {name} there is a {'file' if folder else 'folder'}; the campaign "
                             f"writes a {'folder' if folder else 'file'} of that name (move it away)")
    try:
        meta = json.loads(path.read_text())
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"resume {directory}: campaign.json is not JSON ({exc})") from None
    if not isinstance(meta, dict) or not all(k in meta for k in ("config", "query_set", "expected_experiments")):
        raise ValueError(f"resume {directory}: campaign.json is not a campaign's (no config/query_set)")
    if "query_data" not in meta:
        raise ValueError(f"resume {directory}: written by an older version (no query_data): cannot resume")
    if not isinstance(meta["config"], dict):
        raise ValueError(f"resume {directory}: campaign.json has a bad config (not an object)")
    if "seed" not in meta["config"]:  # a default would silently run other queries' runs than the campaign's
        raise ValueError(f"resume {directory}: campaign.json's config has no seed (every query's runs derive from it)")
    meta["config"].setdefault("problem", "wearer")  # written before campaigns had problems
    try:
        config = CampaignConfig(**{k: tuple(v) if isinstance(v, list) else v for k, v in meta["config"].items()})
    except (TypeError, ValueError) as exc:
        raise ValueError(f"resume {directory}: campaign.json has a bad config ({exc})") from None
    from .problems import get_problem

    bad = _bad_query_data(meta["query_data"], get_problem(config.problem).dimension)
    if bad:
        raise ValueError(f"resume {directory}: campaign.json has bad query_data ({bad})")
    return meta


def _bad_query_data(rows: object, n: int) -> str | None:
    """What is wrong with a campaign's ``query_data`` (a list of queries, each with an ``id`` and a finite
    ``start`` and ``goal`` of the problem's dimension ``n``), or None."""
    if not isinstance(rows, list) or not rows:
        return "not a non-empty list"
    for k, q in enumerate(rows):
        if not isinstance(q, dict):
            return f"entry {k} is not an object"
        if not isinstance(q.get("id"), (int, str)) or isinstance(q.get("id"), bool):
            return f"entry {k} has no id"
        for end in ("start", "goal"):
            v = q.get(end)
            if (not isinstance(v, list) or len(v) != n
                    or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in v)):
                return f"entry {k}: {end} is not {n} finite numbers"
    return None
