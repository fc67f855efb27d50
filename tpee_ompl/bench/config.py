"""What a benchmark campaign runs (:class:`CampaignConfig`), where it wrote (:class:`CampaignResult`),
and the names the campaign knows: planners, motion validators, progress columns.

Imports no OMPL: the command-line parser (``tpee-ompl --help``) is built from this module alone.
The command line takes its defaults from :class:`CampaignConfig`'s fields (one source).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path

__all__ = [
    "ANYTIME_PLANNERS",
    "CHECKERS",
    "CLI_PLANNER_NAMES",
    "CampaignConfig",
    "CampaignResult",
    "ITERATION_PLANNERS",
    "PROGRESS_PROPERTIES",
    "default_workers",
]

ITERATION_PLANNERS = ("DimensionRRT", "RRTstar")
"""Planners of the iteration-matched (Table 4) comparison: dimension-RRT first, the reference second."""
CLI_PLANNER_NAMES: dict[str, str] = {
    "dimension-rrt": "DimensionRRT",
    "rrtstar": "RRTstar",
    "informedrrtstar": "InformedRRTstar",
    "rrtconnect": "RRTConnect",
    "aorrtc": "AORRTC",
    "bitstar": "BITstar",
}
"""``tpee-ompl plan --planner`` name -> benchmark planner name (= OMPL class name; dimension-RRT is ours).
The planners of :data:`ANYTIME_PLANNERS`, in the same order."""
ANYTIME_PLANNERS: tuple[str, ...] = tuple(CLI_PLANNER_NAMES.values())
"""Planners of the time-matched comparison (every planner the command line knows)."""
CHECKERS = ("batched", "discrete")
"""Motion validators: one batched Pinocchio call per motion, or OMPL's DiscreteMotionValidator."""
PROGRESS_PROPERTIES = ["best cost REAL", "iterations INTEGER", "time REAL"]  # sorted, as OMPL's map
"""Columns of the ``progress`` table (name and SQL type, as OMPL's log writes them)."""


def default_workers() -> int:
    """Default worker processes: two, or one on a single-core machine."""
    return max(1, min(2, os.cpu_count() or 1))


@dataclass(frozen=True)
class CampaignConfig:
    """What one campaign runs.  Times in seconds, caps in samples (= RRT* iterations)."""

    name: str = "bench"
    """Folder suffix: ``<out>/<UTC timestamp>_<name>/``."""
    queries: str = "planning_necessary"
    """Query-set name (packaged ``data/queries/<name>.json``) or a JSON file path."""
    sample_caps: tuple[int, ...] = (500, 1000, 1500, 2000, 2500)
    iteration_planners: tuple[str, ...] = ITERATION_PLANNERS
    checkers: tuple[str, ...] = CHECKERS
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
