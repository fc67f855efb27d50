"""The recording wrapper: the first exact solution's time of native planners, read at every termination check."""

from __future__ import annotations

import math
import time

import pytest
from ompl import base as ob
from ompl import geometric as og

from tests.helpers.planning_spaces import box_problem
from tpee_ompl.bench.planners import RecordingPlanner
from tpee_ompl.planning.dimension_rrt import DimensionRRT


def _wrapped_box_planner(make_inner, **wrapper_options) -> tuple[RecordingPlanner, ob.ProblemDefinition, tuple]:
    """``make_inner(si)`` in a set-up :class:`RecordingPlanner` on the box problem, from (-0.9, 0) to (0.9, 0),
    path length objective; with the objects to keep alive."""
    si, checker = box_problem()
    pdef = ob.ProblemDefinition(si)
    start, goal = si.allocState(), si.allocState()
    start[0], start[1], goal[0], goal[1] = -0.9, 0.0, 0.9, 0.0
    pdef.setStartAndGoalStates(start, goal, 1e-9)
    pdef.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    w = RecordingPlanner(si, make_inner(si), **wrapper_options)
    w.setProblemDefinition(pdef)
    w.setup()
    return w, pdef, (si, checker, start, goal)


def _solve(planner_cls, seconds: float, cap: int | None = None) -> dict:
    w, pdef, keep = _wrapped_box_planner(planner_cls, max_iterations=cap)
    t0 = time.perf_counter()
    status = w.solve(ob.timedPlannerTerminationCondition(seconds))
    return dict(w.last, status=str(status), exact=pdef.hasExactSolution(), elapsed=time.perf_counter() - t0, keep=keep)


@pytest.mark.parametrize("planner_cls", [og.RRTstar, og.AORRTC])
def test_native_anytime_planners_record_their_first_exact_solution_before_the_run_ends(planner_cls):
    rec = _solve(planner_cls, 0.5)
    assert rec["exact"] and rec["first_solution_time"] is not None
    # found early (milliseconds on this problem), then improved until the time limit: not the run's end
    assert 0.0 < rec["first_solution_time"] < rec["elapsed"] / 2


def test_rrtconnect_first_solution_is_the_end_of_its_run():
    rec = _solve(og.RRTConnect, 1.0)
    assert rec["exact"] and rec["first_solution_time"] is not None and math.isfinite(rec["first_solution_time"])


def test_a_graph_the_planner_does_not_report_is_null_not_empty():
    """AORRTC's planner data hold no state after a run that made hundreds: the DB said its graph was empty."""
    aorrtc, rrtstar = _solve(og.AORRTC, 0.1), _solve(og.RRTstar, 0.1)
    assert aorrtc["exact"] and aorrtc["graph_states"] is None and aorrtc["graph_motions"] is None
    assert rrtstar["graph_states"] > 1 and rrtstar["graph_motions"] > 0


def test_a_run_without_an_exact_solution_records_no_first_solution_time():
    rec = _solve(og.RRTstar, 5.0, cap=1)  # one iteration: no path from one sample
    assert not rec["exact"] and rec["first_solution_time"] is None


def test_a_runs_checks_are_counted_as_its_solve_returns_not_after_ompls_simplification():
    from ompl import tools as ot

    si, box = box_problem()

    class Counter:  # the campaign's checkers expose a ``collision_checks`` counter
        @property
        def collision_checks(self) -> int:
            return box.calls

    ss = og.SimpleSetup(si)
    start, goal = si.allocState(), si.allocState()
    start[0], start[1], goal[0], goal[1] = -0.9, 0.0, 0.9, 0.0
    ss.setStartAndGoalStates(start, goal, 1e-9)
    w = RecordingPlanner(si, og.RRTConnect(si), checker=Counter())
    bench = ot.Benchmark(ss, "checks")
    bench.addPlanner(w)
    before, after = [], []
    bench.setPreRunEvent(lambda p: before.append(box.calls))
    bench.setPostRunEvent(lambda p, run: after.append(box.calls))
    bench.benchmark(ot.Request(maxTime=1.0, maxMem=4096.0, runCount=1, displayProgress=False,
                               saveConsoleOutput=False, simplify=True))
    assert before[0] < w.last["checks_end"] < after[0]  # OMPL's simplification checks states after the run


def _run_past_benchmarks_deadline(make_inner, deadline: float) -> tuple[RecordingPlanner, list[bool], float]:
    """Solve under a condition that stands for ``ot.Benchmark``'s thread (it looks at its deadline only every 0.1 s):
    it never fires, but for a 5 s safety stop, which it records when reached.  The solve starts 0.3 s after the
    wrapper was built and set up, so a deadline counted from there would stop it at once.  Returns the
    wrapper, the safety record and the solve's seconds."""
    w, pdef, keep = _wrapped_box_planner(make_inner, deadline=deadline)
    time.sleep(0.3)
    safety: list[bool] = []
    t0 = time.perf_counter()

    def benchmark_thread() -> bool:
        if time.perf_counter() - t0 > 5.0:
            safety.append(True)
        return bool(safety)

    w.solve(ob.PlannerTerminationCondition(benchmark_thread))
    elapsed = time.perf_counter() - t0
    w.keep = (pdef, keep)
    return w, safety, elapsed


@pytest.mark.parametrize("make_inner", [og.RRTstar, og.AORRTC, lambda si: DimensionRRT(si, groups=[[0, 1]], seed=1)],
                         ids=["RRTstar", "AORRTC", "DimensionRRT"])
def test_the_run_deadline_stops_the_inner_planner_when_the_benchmarks_own_condition_does_not(make_inner):
    w, safety, elapsed = _run_past_benchmarks_deadline(make_inner, 0.2)
    # stopped by the wrapper's own timed condition (not the 5 s safety), counted from the solve (not before it)
    assert not safety and w.last["error"] is None and elapsed >= 0.2
    assert w.last["best_cost"] is not None and math.isfinite(w.last["best_cost"])  # it ran: found a path first


@pytest.mark.parametrize(("variant", "setting", "value", "default"), [
    ("DimensionRRTReleased", "release_after", "100", "None"),
    ("DimensionRRTNoShortcuts", "shortcuts", "False", "True"),  # on by default: Table 3 prescribes DOF1/DOF2
])
def test_dimension_rrt_variants_are_the_problems_dimension_rrt_with_one_setting_changed_under_their_own_name(
        robot, variant: str, setting: str, value: str, default: str) -> None:
    from tpee_ompl.bench.planners import PlannerContext, planner_factory
    from tpee_ompl.planning.dimension_rrt import RELEASE_AFTER
    from tpee_ompl.planning.setup import make_simple_setup

    assert RELEASE_AFTER == 100
    si = make_simple_setup(robot).getSpaceInformation()
    ctx = PlannerContext(query={"from_sector": 1, "to_sector": 4}, max_samples=500, seed=3)
    plain, other = planner_factory("DimensionRRT")(si, ctx), planner_factory(variant)(si, ctx)
    assert other.getName() == variant and plain.getName() == "DimensionRRT"
    assert other.settings()[setting] == value and plain.settings()[setting] == default
    assert {k: v for k, v in other.settings().items() if k != setting} == \
        {k: v for k, v in plain.settings().items() if k != setting}


def test_the_planners_refused_at_a_sample_cap_are_those_whose_bindings_count_no_iterations():
    """``NOT_ITERATION_CAPPED`` is checked against the bindings: a native planner is there iff it has no
    ``numIterations()`` (an AORRTC in the sample ladder killed every worker with SIGSEGV)."""
    from ompl import geometric as og

    from tpee_ompl.bench.config import KNOWN_PLANNERS, NOT_ITERATION_CAPPED

    for name in KNOWN_PLANNERS:
        native = getattr(og, name, None)
        if native is not None:
            assert (name in NOT_ITERATION_CAPPED) == (not hasattr(native, "numIterations")), name
    assert "RRTConnectSimplify" in NOT_ITERATION_CAPPED


def test_a_python_planners_settings_are_one_line_each_in_the_log():
    from tpee_ompl.bench.planners import planner_settings

    class P:
        def settings(self):
            return {"note": "line one\nline two", "multi  word\tkey": 3}

    assert planner_settings(P()) == {"note": "line one line two", "multi word key": "3"}


@pytest.mark.parametrize("name", ["os:system", "math:hypot", "json:dumps"])
def test_a_callable_that_cannot_take_si_and_ctx_is_refused_when_named(name):
    """`--planners os:system` ran every query of a campaign, each failing with the same TypeError."""
    from tpee_ompl.bench.planners import planner_factory

    if name == "math:hypot":  # takes any number of arguments: only its result can tell, when it is called
        assert planner_factory(name) is __import__("math").hypot
        return
    with pytest.raises(ValueError, match=r"cannot be called as factory\(si, ctx\)"):
        planner_factory(name)


def test_a_factory_with_two_parameters_is_taken():
    from helpers.bench_standins import make_standin

    from tpee_ompl.bench.planners import planner_factory

    assert planner_factory("helpers.bench_standins:make_standin") is make_standin
