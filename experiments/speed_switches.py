"""Speed changes that keep every path: the same capped runs with a switch in each setting, same samples, same paths.

    PYTHONPATH=. .venv/bin/python experiments/speed_switches.py look-ahead                    # ~1 min
    PYTHONPATH=. .venv/bin/python experiments/speed_switches.py look-ahead --samples 20000 --reps 1
    PYTHONPATH=. .venv/bin/python experiments/speed_switches.py candidate-stride --values 16 8 4 2
    PYTHONPATH=. .venv/bin/python experiments/speed_switches.py candidate-stride --planner paper --samples 2500
    PYTHONPATH=. .venv/bin/python experiments/speed_switches.py hit-states --samples 20000 --reps 1
    PYTHONPATH=. .venv/bin/python experiments/speed_switches.py screen-order --samples 20000 --reps 1
    PYTHONPATH=. .venv/bin/python experiments/speed_switches.py pair-checks --planner paper --samples 2500
    PYTHONPATH=. .venv/bin/python experiments/speed_switches.py broadphase --planner paper --samples 2500

Switches (scratch settings of the installed code; the first value is the reference):

* ``look-ahead`` (``on``, ``off``): on a valid path the search passes over the samples that are shorter at
  no step with one vectorised cost test (``SampleDraws._pass_rejected``); ``on`` runs it ahead over up
  to ``AHEAD`` samples and keeps it while the path stays the same (the package); ``off`` drops the kept
  test before every call, so each call tests its own window of at most 63 samples (before 2026-11-26;
  exactly so with one planned group, as in both planners here: with several, the window still runs to
  the end of the group's block).
* ``candidate-stride`` (default values ``4 16``): the improvement phase screens one candidate's two
  motions at every N-th interior state, longest stretch first, up to the first failure, before the
  validator checks them in full (``search_checker._CANDIDATE_STRIDE``; 16 before 2026-11-26).
* ``hit-states`` (``on``, ``off``): with a group of every DOF (the released search) the look-ahead checks the
  states of the samples its cost test lets through in one call (``SampleDraws._hit_states``, the package);
  ``off``: each is checked when its turn comes, one call per sample (before 2026-11-26).
* ``screen-order`` (``nearest``, ``bisect``): the screens in bisection order check the states nearest the
  last colliding state a screen found first (``search_checker._NEAREST_FIRST``, the package), or always
  longest stretch first (before 2026-11-26).  A lone candidate's verdict is the same either way; a
  candidate path of the feasibility phase may report another failing motion, so with a search that has no
  valid path at first the paths may differ (then ``PATHS DIFFER`` is expected).
* ``pair-checks`` (``on``, ``off``): ``RobotChecker.first_invalid`` (every screen that stops at its first
  failure) checks its rows two at a time, one per thread (``robot_checker.FIRST_INVALID_PAIRS``, the
  package), or one at a time on one thread (before 2026-11-26).  The same answers, so the same paths; the
  checks count both rows of the last pair.
* ``broadphase`` (``on``, ``off``): the robot's batched and single checks and its clearance balls' screens through
  Pinocchio's tree broadphase (``collision_pools.BROADPHASE``, the package), or every active pair narrow-phased
  (before 2026-11-28).  The same verdicts, so the same paths and checks.

Each run is capped at ``--samples``, so every setting draws the same samples; the paths must be the same
(their states' bytes compared, and printed).  Settings alternate per query.  Prints the total time, the collision checks and
the ratio to the first value.  ``--planner library``: ``LibraryDimensionRRT`` (Table 3's rows released
after ``RELEASE_AFTER``); ``paper``: ``tpee_dimension_rrt`` (rows kept, Table 4's planner).
"""

from __future__ import annotations

import argparse
import hashlib
import time
from collections.abc import Callable

import numpy as np
from _common import summary, wearer_library_queries
from ompl import util as ou

from tpee_ompl import make_simple_setup
from tpee_ompl.library.planner import LibraryDimensionRRT
from tpee_ompl.model import collision_pools, robot_checker
from tpee_ompl.planning import search_checker, search_draws
from tpee_ompl.planning.paths import path_to_array
from tpee_ompl.planning.tpee import tpee_dimension_rrt

_KEPT = search_draws.SampleDraws._pass_rejected


def _per_call(self, limit: int) -> None:
    """``_pass_rejected`` without the look-ahead: the kept test dropped, a window of ``limit`` samples."""
    self._ahead = None
    saved, search_draws.AHEAD = search_draws.AHEAD, max(1, limit)
    try:
        _KEPT(self, limit)
    finally:
        search_draws.AHEAD = saved


def _look_ahead(value: str) -> None:
    search_draws.SampleDraws._pass_rejected = _KEPT if value == "on" else _per_call


def _candidate_stride(value: str) -> None:
    search_checker._CANDIDATE_STRIDE = int(value)


_HIT_STATES = search_draws.SampleDraws._hit_states


def _hit_states(value: str) -> None:
    search_draws.SampleDraws._hit_states = _HIT_STATES if value == "on" else (lambda self, S, last: {})


def _screen_order(value: str) -> None:
    search_checker._NEAREST_FIRST = value == "nearest"


def _pair_checks(value: str) -> None:
    robot_checker.FIRST_INVALID_PAIRS = value == "on"


_ROBOT: list = []  # the run's robot, for the switches that rebuild its pools
_POOLS: dict[str, tuple] = {}


def _broadphase(value: str) -> None:
    """The robot's pools, single check and ball screen built with the broadphase on or off (each kept once built)."""
    robot = _ROBOT[0]
    if value not in _POOLS:
        with collision_pools.broadphase(value == "on"):
            _POOLS[value] = (collision_pools.new_pool(robot.model, robot.gmodel, robot.gdata, robot.n_threads),
                             collision_pools.single_check(robot.model, robot.data, robot.gmodel, robot.gdata), None)
    if robot._ball_screen is not None:
        old = next(k for k, v in _POOLS.items() if v[0] is robot.pool)
        _POOLS[old] = (*_POOLS[old][:2], robot._ball_screen)
    robot.pool, robot._collides, robot._ball_screen = _POOLS[value]
    collision_pools.BROADPHASE = value == "on"  # a ball screen built from here on takes the same kind of pools


SWITCHES: dict[str, tuple[Callable[[str], None], list[str]]] = {
    "look-ahead": (_look_ahead, ["on", "off"]),
    "candidate-stride": (_candidate_stride, ["4", "16"]),
    "hit-states": (_hit_states, ["on", "off"]),
    "screen-order": (_screen_order, ["nearest", "bisect"]),
    "pair-checks": (_pair_checks, ["on", "off"]),
    "broadphase": (_broadphase, ["on", "off"]),
}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("switch", choices=sorted(SWITCHES))
    defaults = "; ".join(f"{k}: {' '.join(v)}" for k, (_, v) in sorted(SWITCHES.items()))
    ap.add_argument("--values", nargs="+",
                    help=f"settings to compare, the reference first (default per switch: {defaults})")
    ap.add_argument("--queries", default="planning_necessary")
    ap.add_argument("--max-queries", type=int, default=24)
    ap.add_argument("--samples", type=int, default=5000, help="sample cap per run")
    ap.add_argument("--planner", choices=("library", "paper"), default="library")
    ap.add_argument("--reps", type=int, default=2)
    args = ap.parse_args(argv)
    apply, default = SWITCHES[args.switch]
    values = args.values or default
    ou.setLogLevel(ou.LOG_NONE)
    robot, lib, rows = wearer_library_queries(args.queries, args.max_queries)
    _ROBOT[:] = [robot]
    _POOLS["on"] = (robot.pool, robot._collides, None)  # the package's own (its ball screen is kept on switching)
    setups = [make_simple_setup(robot, np.array(q["start"]), np.array(q["goal"])) for q in rows]
    total = dict.fromkeys(values, 0.0)
    checks = dict.fromkeys(values, 0)
    paths: dict[str, list[str]] = {v: [] for v in values}
    for rep in range(args.reps):
        for k, (q, ss) in enumerate(zip(rows, setups)):
            for value in (values if (k + rep) % 2 else values[::-1]):
                apply(value)
                si = ss.getSpaceInformation()
                if args.planner == "library":
                    planner = LibraryDimensionRRT(si, lib, q["from_sector"], q["to_sector"], seed=k,
                                                  max_samples=args.samples)
                else:
                    planner = tpee_dimension_rrt(si, q["from_sector"], q["to_sector"], seed=k, max_samples=args.samples)
                ss.clear()
                ss.setPlanner(planner)
                c0, t0 = robot.collision_checks, time.perf_counter()
                ss.solve(60.0)
                total[value] += time.perf_counter() - t0
                checks[value] += robot.collision_checks - c0
                W = path_to_array(ss.getSolutionPath(), robot.nq) if ss.haveExactSolutionPath() else None
                paths[value].append(hashlib.sha256(b"" if W is None else W.tobytes()).hexdigest())
    apply(default[0])
    ref = values[0]
    print(f"{args.switch}, {args.planner}, {len(rows)} queries x {args.reps}, {args.samples} samples per run:")
    for v in values:
        same = "same paths" if paths[v] == paths[ref] else "PATHS DIFFER"
        print(f"  {v:>7}: {total[v]:6.2f} s  ratio {total[v] / total[ref]:.3f}  checks {checks[v]}  {same}")


if __name__ == "__main__":
    main()
