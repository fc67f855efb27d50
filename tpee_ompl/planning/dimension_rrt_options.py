"""The settings of :class:`~tpee_ompl.planning.dimension_rrt.DimensionRRT`, checked once (what each does:
that module's docstring and ``docs/dimension_rrt.md``)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..validation import check_bool, check_int, check_name, check_number
from ..validation import resolve_options as resolve
from .grouped_space import MAX_H, group_lists

__all__ = ["RELEASE_AFTER", "RESTART_AFTER", "DimensionRRTOptions", "resolve_options", "shortcuts_on"]

RELEASE_AFTER = 100
"""A ``release_after`` that pays (the library pipeline's default; chosen on 36 held-out queries, ``docs/dimension_rrt.md``)."""
RESTART_AFTER = 2000
"""A ``restart_after`` measured on the generic problems (``experiments/restarts.py``, ``docs/dimension_rrt.md``)."""


@dataclass(frozen=True)
class DimensionRRTOptions:
    """Settings of :class:`~tpee_ompl.planning.dimension_rrt.DimensionRRT`, checked once here (the sections
    named below are those of that module's docstring).

    Attributes
    ----------
    groups : sequence of sequences of int, optional
        DOF indices per group in planning order (default ``[[0, 1], [2, 3]]`` for 4-D, else pairs).
    h : int
        Fake-time steps including start and goal (default 7, the length of the Table 3 rows).
    max_samples : int, optional
        Stop after this many samples even if the termination condition still allows time.
    seed : int, optional
        Seed of the planner's own ``np.random.Generator`` (OMPL's seed does not cover it).  Its stream runs
        on across solves and ``clear()``, so a benchmark's runs of one planner differ, as OMPL's planners'
        do; a new planner with the same seed repeats the first solve.
    narrow_after : int
        Samples of a group (and a valid path) before its sampling region narrows (default 200).
    narrowing : float in (0, 1]
        Factor by which the padding of the narrowed region shrinks every 100 samples (default 0.5).
    range_ : float or sequence of float, optional
        Smallest padding of the narrowed region, in the DOFs' units (default 2 % of each bound width).
    name : str
        Planner name (``geometric_<name>`` in a Benchmark database).
    batch : bool
        Use the checker's batched ``are_valid`` when it has one (default True).
    stall_samples : int, optional
        Stop after this many samples in a row without a shorter valid path (None: as the paper, never);
        with several goal states, per goal state (see "Goal regions").
    max_h : int, optional
        Largest number of fake-time steps the feasibility phase may raise ``h`` to, at least ``h`` (None,
        the default: ``h`` stays fixed, as in the paper).  See "Raising h".
    connect : bool
        Without prescribed groups, look for the first path with RRTConnect's two trees and fit it to
        the ``h`` steps (default True); False: the layered trees.  See "Feasibility phase".
    release_after : int, optional
        After this many samples in a row without a shorter valid path, the prescribed rows are
        released (None, the default: kept to the end, as in the paper).  See "Releasing the prescribed rows".
    shortcuts : bool, optional
        After each improvement, move every intermediate waypoint towards the point shortest between its
        neighbours (None, the default: only with a prescribed group, where it pays).  See "Shortcuts".
    max_goals : int
        Most goal states drawn from a goal region that is not one state (``GoalStates``, another
        ``GoalSampleableRegion``); one search per goal state (default 8).  See "Goal regions".
    restart_after : int, optional
        Without a prescribed group: after this many samples in a row without a shorter path, a fresh search of the
        goal takes turns with the converged one, and is started again whenever it converges no shorter (None, the
        default: one search, as in the paper, whose rule only shortens a path where it lies).  See "Restarts".
    """

    groups: Sequence[Sequence[int]] | None = None
    h: int = 7
    max_samples: int | None = None
    seed: int | None = None
    narrow_after: int = 200
    narrowing: float = 0.5
    range_: float | Sequence[float] | None = None
    name: str = "DimensionRRT"
    batch: bool = True
    stall_samples: int | None = None
    max_h: int | None = None
    connect: bool = True
    release_after: int | None = None
    shortcuts: bool | None = None
    max_goals: int = 8
    restart_after: int | None = None

    def __post_init__(self) -> None:
        check_name("name", self.name)
        set_ = lambda field_, value: object.__setattr__(self, field_, value)  # noqa: E731 (frozen dataclass)
        if self.groups is not None:  # their form here; that they cover the space's DOFs, once the space is known
            set_("groups", tuple(tuple(g) for g in group_lists(self.groups)))
        set_("h", check_int("h (fake-time steps incl. start and goal)", self.h, minimum=3, maximum=MAX_H))
        set_("max_samples", check_int("max_samples", self.max_samples, minimum=1, optional=True))
        set_("seed", check_int("seed", self.seed, minimum=0, optional=True))
        set_("narrow_after", check_int("narrow_after", self.narrow_after, minimum=0))
        set_("narrowing", check_number("narrowing", self.narrowing, low=0.0, high=1.0, low_open=True))
        set_("batch", check_bool("batch", self.batch))
        set_("connect", check_bool("connect", self.connect))
        if self.shortcuts is not None:
            set_("shortcuts", check_bool("shortcuts", self.shortcuts))
        set_("stall_samples", check_int("stall_samples", self.stall_samples, minimum=1, optional=True))
        set_("max_h", check_int("max_h", self.max_h, minimum=3, maximum=MAX_H, optional=True))
        if self.max_h is not None and self.max_h < self.h:
            raise ValueError(f"max_h must be at least h ({self.h}), got {self.max_h}")
        set_("release_after", check_int("release_after", self.release_after, minimum=1, optional=True))
        set_("max_goals", check_int("max_goals", self.max_goals, minimum=1))
        set_("restart_after", check_int("restart_after", self.restart_after, minimum=1, optional=True))
        if self.range_ is not None:
            try:
                arr = np.asarray(self.range_, dtype=float)
            except (TypeError, ValueError):
                arr = None
            if arr is None or arr.ndim > 1 or arr.size == 0 or not np.all(np.isfinite(arr)) or np.any(arr <= 0):
                raise ValueError(f"range_ must be a positive number or array, got {self.range_!r}")


def shortcuts_on(options: DimensionRRTOptions, prescribed: bool) -> bool:
    """Whether the search takes shortcuts between waypoints: ``options.shortcuts``, or when it is None,
    whether a group is prescribed (where they pay; see "Shortcuts")."""
    return prescribed if options.shortcuts is None else options.shortcuts


def resolve_options(options: DimensionRRTOptions | None, overrides: Mapping[str, Any]) -> DimensionRRTOptions:
    """``options`` (default settings if None) with the keyword overrides applied, validated."""
    return resolve(DimensionRRTOptions, options, overrides)
