"""Exact solutions of every planner we ship or wrap, checked at 1x and 4x the setup resolution on one query per pair.

OMPL's ``correct_solution_strict`` benchmark column as a test on these queries and seeds: each segment of
an exact path passes ``si.checkMotion`` at the setup's resolution, again with the space's
``validSegmentCountFactor`` at 4 (what ``ot.Benchmark`` does), and, independently of OMPL, at a quarter of
the joint step with ``motion_states`` + ``robot.are_valid``.  Queries come from the ``planning_necessary``
set (its straight motion collides), spread over the 12 sector pairs.  The 1x check is the guarantee; 4x
is not one in general: a path pulled tight along the margin can dip a few hundredths of a millimetre below
it between two checked states (README, "Guarantees": how often in the campaigns), so dimension-RRT's
paths (pulled tight by its shortcut sweeps) are held to the guarantee itself there: every quarter-step
state keeps each pair at least half its margin apart.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl.planning.tpee import tpee_dimension_rrt
from tpee_ompl.planning.setup import make_simple_setup, motion_check_step
from tpee_ompl.planning.paths import motion_states, path_passes_motion_checks, path_to_array
from tpee_ompl.model.queries import Query, load_queries
from tpee_ompl.model.wearer_arm import WearerArm

PER_PAIR = 10
"""Queries per ordered sector pair in the stored set (query k * 10 is the first of pair k)."""


@pytest.fixture(scope="module")
def queries(robot: WearerArm) -> list[Query]:
    """The planning-necessary set, refused if it was made for another model."""
    qs = load_queries("planning_necessary", robot)
    assert len(qs) == 12 * PER_PAIR
    return qs


def _least_margin_fraction(robot: WearerArm, Q: np.ndarray) -> float:
    """Smallest over the states Q and the checked pairs of the pair's distance / its security margin."""
    import pinocchio as pin

    data, gd = robot.model.createData(), pin.GeometryData(robot.gmodel)
    margins = robot.pair_margins()
    least = np.inf
    for q in Q:
        pin.computeDistances(robot.model, data, robot.gmodel, gd, q)
        least = min(least, float((np.array([r.min_distance for r in gd.distanceResults]) / margins).min()))
    return least


def _strict_failures(robot: WearerArm, ss: og.SimpleSetup, q: Query, tight: bool = False) -> list[str]:
    """Reasons the setup's exact solution is not a correct strict solution (empty if it is).

    ``tight``: a path pulled tight along the margin may fail the 4x and quarter-step checks, so long as
    every quarter-step state keeps each pair at least half its margin apart (the guarantee the 1x check
    gives, README "Guarantees")."""
    si = ss.getSpaceInformation()
    path = ss.getSolutionPath()
    W = path_to_array(path, robot.nq)
    problems: list[str] = []
    if len(W) < 2 or not (np.allclose(W[0], q.start, atol=1e-9) and np.allclose(W[-1], q.goal, atol=1e-6)):
        problems.append(f"path of {len(W)} states does not run from start to goal")
        return problems
    if not robot.are_valid(W).all():
        problems.append("a waypoint is invalid")
    if not path_passes_motion_checks(si, path):
        problems.append("si.checkMotion rejects a segment at the setup resolution")
    space = si.getStateSpace()
    factor = space.getValidSegmentCountFactor()
    space.setValidSegmentCountFactor(4 * factor)  # as ompl::tools::Benchmark for correct_solution_strict
    try:
        if not path_passes_motion_checks(si, path) or not path.check():
            problems.append("si.checkMotion rejects a segment at 4x the resolution")
    finally:
        space.setValidSegmentCountFactor(factor)
    step = motion_check_step(ss) / 4  # the setup's joint step, quartered
    dense = np.concatenate([motion_states(a, b, step) for a, b in zip(W[:-1], W[1:])])
    if not robot.are_valid(dense).all():
        problems.append("a state at a quarter of the joint step collides")
    if tight and problems and all("4x" in p or "quarter" in p for p in problems):
        least = _least_margin_fraction(robot, dense)  # every quarter-step state, valid ones included
        return [] if least >= 0.5 else [f"a state at a quarter of the joint step keeps only {least:.3f} of a margin"]
    return problems


def _run(robot: WearerArm, q: Query, make: Callable[[ob.SpaceInformation, Query], ob.Planner], seconds: float):
    ss = make_simple_setup(robot, q.start, q.goal)
    planner = make(ss.getSpaceInformation(), q)
    ss.setPlanner(planner)
    pdef = ss.getProblemDefinition()
    ptc = ob.plannerOrTerminationCondition(
        ob.timedPlannerTerminationCondition(seconds), ob.exactSolnPlannerTerminationCondition(pdef)
    )
    ss.solve(ptc)
    return ss


def test_dimension_rrt_exact_paths_pass_strict_check_on_all_12_pairs(robot: WearerArm, queries: list[Query]) -> None:
    exact = 0
    for pair in range(12):
        q = queries[pair * PER_PAIR + pair % PER_PAIR]
        ss = make_simple_setup(robot, q.start, q.goal)
        ss.setPlanner(tpee_dimension_rrt(ss.getSpaceInformation(), q.from_sector, q.to_sector, max_samples=120, seed=pair))
        ss.solve(10.0)
        if ss.haveExactSolutionPath():
            exact += 1
            # its shortcut sweeps pull paths tight along the margin: 4x dips allowed, within the guarantee
            assert _strict_failures(robot, ss, q, tight=True) == [], (q.id, q.from_sector, q.to_sector)
    assert exact >= 10, f"only {exact}/12 exact solutions: the strict check tested too little"


NATIVE = {
    "RRTConnect": (og.RRTConnect, 2.0, 0),
    "RRTstar": (og.RRTstar, 1.5, 1),
    "InformedRRTstar": (og.InformedRRTstar, 1.5, 2),
    "BITstar": (og.BITstar, 1.5, 3),
}
SLOW = {"RRTstar", "InformedRRTstar", "BITstar"}
"""These use their whole time budget (3 x 1.5 s)."""


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n in SLOW else n for n in sorted(NATIVE)])
def test_native_planner_exact_paths_pass_strict_check(robot: WearerArm, queries: list[Query], name: str) -> None:
    cls, seconds, offset = NATIVE[name]
    ou.RNG.setSeed(17)
    exact = 0
    for pair in range(offset, 12, 4):  # three pairs per planner, all 12 pairs over the four planners
        q = queries[pair * PER_PAIR + offset]
        ss = _run(robot, q, lambda si, _q: cls(si), seconds)
        if ss.haveExactSolutionPath():
            exact += 1
            assert _strict_failures(robot, ss, q) == [], (name, q.id)
    if name in ("RRTConnect", "BITstar"):  # these find exact paths in well under their budget
        assert exact >= 1, f"{name}: {exact}/3 exact solutions: the strict check tested nothing"


def test_aorrtc_exact_paths_are_strict_or_rejected(robot: WearerArm, queries: list[Query]) -> None:
    """AORRTC may report zero-length 'exact' paths (ompl/ompl#1420): the strict check must catch any."""
    ou.RNG.setSeed(5)
    for pair in (1, 6, 11):
        q = queries[pair * PER_PAIR + 3]
        ss = _run(robot, q, lambda si, _q: og.AORRTC(si), 1.0)
        if not ss.haveExactSolutionPath():
            continue
        W = path_to_array(ss.getSolutionPath(), robot.nq)
        failures = _strict_failures(robot, ss, q)
        if len(W) < 2 or np.allclose(W[0], W[-1]):  # the upstream bug: must not pass as valid
            assert failures, f"zero-length AORRTC path passed the strict check (query {q.id})"
        else:
            assert failures == [], (q.id, failures)


def test_zero_length_path_to_a_different_goal_fails_the_strict_check(robot: WearerArm, queries: list[Query]) -> None:
    """What ompl/ompl#1420 returns (a path that stays at the start) is never taken as a valid solution."""
    q = queries[0]
    ss = make_simple_setup(robot, q.start, q.goal)
    si = ss.getSpaceInformation()
    for n in (1, 2):
        path = og.PathGeometric(si)
        for _ in range(n):
            s = si.allocState()
            for i, v in enumerate(q.start):
                s[i] = float(v)
            path.append(s)
        ss.getProblemDefinition().clearSolutionPaths()
        ss.getProblemDefinition().addSolutionPath(path, False, 0.0, "zero_length")
        assert ss.haveExactSolutionPath()  # OMPL itself takes the planner's word for it
        assert _strict_failures(robot, ss, q), f"a {n}-state zero-length path passed"


def test_strict_check_really_is_denser_than_the_setup_resolution(robot: WearerArm) -> None:
    """The 4x factor reaches our batched motion validator (it would silently ignore it otherwise)."""
    ss = make_simple_setup(robot)
    si = ss.getSpaceInformation()
    si.getMotionValidator().screen_levels = ()  # count the dense states themselves
    step = motion_check_step(ss)
    a, b = si.allocState(), si.allocState()
    for i in range(4):
        a[i], b[i] = 0.3, 0.3
    b[2] = 0.3 + 10 * step
    checks0 = robot.collision_checks
    si.checkMotion(a, b)
    coarse = robot.collision_checks - checks0
    si.getStateSpace().setValidSegmentCountFactor(4)
    checks0 = robot.collision_checks
    si.checkMotion(a, b)
    dense = robot.collision_checks - checks0
    si.getStateSpace().setValidSegmentCountFactor(1)
    assert (coarse, dense) == (10, 40)
