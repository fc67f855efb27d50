"""Benchmark problems: the registry, their set-ups and queries, and how a configuration is checked against them."""

from __future__ import annotations

import ast
import gc
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import tpee_ompl.bench.generic_problems as generic
from tpee_ompl.bench.config import CampaignConfig
from tpee_ompl.bench.experiment import group_lengths
from tpee_ompl.bench.generic_problems import GENERIC_PROBLEMS
from tpee_ompl.bench.problems import DEFAULT_PROBLEM, PROBLEM_NAMES, get_problem
from tpee_ompl.planning.space_layout import RealVectorLayout
from tests.helpers.panda import needs_panda

ROBOT_PROBLEMS = ("panda-shelf", "kinova-posts")  # their robots come from the optional 'robots' extra
BUILDABLE = [pytest.param(n, marks=needs_panda) if n in ROBOT_PROBLEMS else n for n in PROBLEM_NAMES]
STRAIGHT_MAY_BE_FREE = {"wearer-random"}  # the paper's random queries: most straight motions are free


def test_registry_lists_the_wearer_first_then_generic_and_robot_problems():
    assert PROBLEM_NAMES[0] == DEFAULT_PROBLEM == CampaignConfig().problem == "wearer"
    assert {"wearer-random", *ROBOT_PROBLEMS, *GENERIC_PROBLEMS} <= set(PROBLEM_NAMES)
    assert len(set(PROBLEM_NAMES)) == len(PROBLEM_NAMES)
    for name in GENERIC_PROBLEMS:
        p = get_problem(name)
        assert p.dimension == GENERIC_PROBLEMS[name].n and p.groups == GENERIC_PROBLEMS[name].groups
        assert p.checkers == ("discrete",) and not p.library
    assert get_problem("arm6").groups == ((0, 1), (2, 3), (4, 5))


def test_unknown_problem_is_a_one_line_error_naming_the_choices():
    with pytest.raises(ValueError, match="unknown problem 'nope': choose from wearer") as exc:
        get_problem("nope")
    assert "\n" not in str(exc.value)
    with pytest.raises(ValueError, match="unknown problem"):
        CampaignConfig(problem="nope")


@pytest.mark.parametrize("name", BUILDABLE)
def test_problem_builds_setups_with_valid_ends_and_a_colliding_straight_motion(name):
    p = get_problem(name)
    set_name, rows = p.queries()
    assert set_name and len(rows) >= 8 and len({q["id"] for q in rows}) == len(rows)
    rows = rows[:10]
    straight_free = 0
    for q in rows:
        assert len(q["start"]) == len(q["goal"]) == p.dimension
        ss, checker = p.make_setup(q, p.checkers[-1] if p.checkers[0] == "discrete" else "discrete")
        si = ss.getSpaceInformation()
        layout = RealVectorLayout(si.getStateSpace())
        a, b = layout.write(si.allocState(), q["start"]), layout.write(si.allocState(), q["goal"])
        before = checker.collision_checks
        assert si.isValid(a) and si.isValid(b)
        straight_free += si.checkMotion(a, b)
        assert checker.collision_checks > before  # every state check is counted
        assert isinstance(checker.model_hash, str) and checker.model_hash
    if name not in STRAIGHT_MAY_BE_FREE:
        assert straight_free == 0
    gc.collect()


def test_generic_queries_are_deterministic_and_plain_data():
    spec = GENERIC_PROBLEMS["arm5-so2"]
    first, again = generic.generic_queries(spec), generic.generic_queries(spec)
    assert first == again and len(first) == spec.n_queries
    assert all(isinstance(v, float) for q in first for v in q["start"] + q["goal"])


def test_generic_problem_set_up_code_imports_no_project_module():
    tree = ast.parse(Path(generic.__file__).read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            assert node.level == 0 and not (node.module or "").startswith("tpee_ompl"), ast.unparse(node)
            assert (node.module or "").split(".")[0] in {"__future__", "collections", "dataclasses", "typing",
                                                          "hashlib", "math", "numpy", "ompl"}, ast.unparse(node)
        elif isinstance(node, ast.Import):
            assert all(a.name.split(".")[0] in {"hashlib", "math", "numpy"} for a in node.names), ast.unparse(node)


def test_generic_problems_have_no_batched_or_certified_validator():
    p = get_problem("arm4")
    _, rows = p.queries()
    for validator in ("batched", "certified"):
        with pytest.raises(ValueError, match=f"problem arm4: motion validator '{validator}' is not one of"):
            p.make_setup(rows[0], validator)
    with pytest.raises(ValueError, match="checkers: problem arm4 has no 'certified'"):
        CampaignConfig.for_problem("arm4", checkers=("certified",))


def test_robot_problems_run_the_certified_validator_only_when_asked():
    assert CampaignConfig().checkers == ("batched", "discrete")
    cfg = CampaignConfig(checkers=("batched", "certified"))
    assert cfg.checkers[1] == "certified"
    ss, _ = get_problem("wearer").make_setup(get_problem("wearer").queries()[1][0], "certified")
    assert type(ss.getSpaceInformation().getMotionValidator()).__name__ == "CertifiedMotionValidator"


def test_robot_problems_run_the_unscreened_batched_validator_as_dense():
    query = get_problem("wearer").queries()[1][0]
    screened = get_problem("wearer").make_setup(query, "batched")[0].getSpaceInformation().getMotionValidator()
    dense = get_problem("wearer").make_setup(query, "dense")[0].getSpaceInformation().getMotionValidator()
    assert screened.screen_levels and dense.screen_levels == ()
    assert CampaignConfig(checkers=("batched", "dense")).checkers == ("batched", "dense")


def test_configuration_refuses_what_a_problem_cannot_run():
    with pytest.raises(ValueError, match="checkers: problem arm4 has no 'batched'"):
        CampaignConfig(problem="arm4", anytime_planners=("RRTConnect",))
    with pytest.raises(ValueError, match="anytime_planners: LibraryDimensionRRT does not apply to problem arm4"):
        CampaignConfig(problem="arm4", checkers=("discrete",))
    with pytest.raises(ValueError, match="AORRTC does not apply to problem arm5-so2"):
        CampaignConfig.for_problem("arm5-so2", anytime_planners=("AORRTC",))
    with pytest.raises(ValueError, match="queries: problem narrow3 has built-in queries"):
        CampaignConfig.for_problem("narrow3", queries="planning_necessary")
    cfg = CampaignConfig.for_problem("arm6")
    assert cfg.checkers == ("discrete",) and "LibraryDimensionRRT" not in cfg.anytime_planners
    assert {"DimensionRRT", "RRTConnect", "RRTConnectSimplify", "RRTstar", "AORRTC", "BITstar"} == set(cfg.anytime_planners)
    assert CampaignConfig.for_problem("wearer") == CampaignConfig()


def test_robot_problem_without_the_robots_extra_fails_with_one_line_naming_it():
    # a fresh process: this one may have loaded the Panda already (the problem caches its checker)
    code = ("import sys; sys.modules['example_robot_data'] = None\n"
            "from tpee_ompl.bench.problems import get_problem, problem_table\n"
            "p = get_problem('panda-shelf'); assert p.dimension == 7 and p.checkers[0] == 'batched'\n"
            "row = next(r for r in problem_table() if r['name'] == 'panda-shelf')\n"
            "assert row['queries'] is None and 'robots' in row['note'], row\n"
            "try:\n    p.queries()\nexcept ImportError as exc:\n    print(exc)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "the Panda needs the optional 'robots' extra: pip install 'tpee-ompl[robots]'"


@needs_panda
def test_the_robot_problems_groups_are_the_robot_modules_groups():
    from tpee_ompl.model.robots import KINOVA_GROUPS, PANDA_GROUPS

    assert get_problem("panda-shelf").groups == PANDA_GROUPS
    assert get_problem("kinova-posts").groups == KINOVA_GROUPS


@needs_panda
@pytest.mark.slow
def test_the_recorded_seed_is_the_experiments_process_seed_on_a_setup_that_draws_nothing(tmp_path):
    """The kinova set-up draws no random number, so OMPL recorded the seed set last, RRT*'s own (4184217888 for
    process seed 1): Planner Arena's ``seed`` column named a seed that made none of the runs."""
    import sqlite3

    from tpee_ompl.bench.campaign import run_campaign

    cfg = CampaignConfig.for_problem("kinova-posts", name="k", sample_caps=(20,), anytime_budgets=(),
                                     checkers=("batched",), max_queries=2, workers=0, seed=7, out=str(tmp_path))
    res = run_campaign(cfg, progress_bar=False, report=False)
    rows = sqlite3.connect(res.database).execute("SELECT seed, process_seed FROM experiments").fetchall()
    assert sorted(rows) == [("7", 7), ("8", 8)]


def test_the_continuous_joint_arm_leaves_out_what_an_so2_compound_cannot_take():
    p = get_problem("kinova-posts")
    assert "certified" not in p.checkers and p.checkers[0] == "batched"
    assert {"AORRTC", "BITstar", "InformedRRTstar"} <= set(p.unsupported)
    assert not {"AORRTC", "BITstar"} & set(p.planners) and "DimensionRRT" in p.planners


def test_group_lengths_of_an_so2_path_go_the_short_way_round():
    spec = GENERIC_PROBLEMS["arm5-so2"]
    ss, _ = generic.make_generic_setup(spec, [3.0] + [0.0] * 4, [-3.0] + [0.0] * 4)
    layout = RealVectorLayout(ss.getSpaceInformation().getStateSpace())
    W = np.array([[3.0, 0, 0, 0, 0], [-3.0, 0, 0, 0.5, 0]])
    whole, first, rest = group_lengths(W, (0, 1), layout)
    assert first == pytest.approx(2 * np.pi - 6.0) and rest == pytest.approx(0.5)
    assert whole == pytest.approx(2 * np.pi - 6.0 + 0.5)  # SO2 compound metric: sum of the angle distances
    gc.collect()


@pytest.mark.slow
def test_campaign_on_a_generic_problem_fills_the_database_with_its_dimension_and_checks(tmp_path):
    import json
    import sqlite3

    from tpee_ompl.bench.campaign import load_campaign, run_campaign

    cfg = CampaignConfig.for_problem("arm6", name="arm6", sample_caps=(100,), anytime_budgets=(0.1,),
                                     anytime_planners=("DimensionRRT", "RRTConnect", "RRTConnectSimplify"),
                                     max_queries=2, workers=0, seed=5, out=str(tmp_path))
    res = run_campaign(cfg, progress_bar=False, report=False)
    assert not res.interrupted and not res.failed_tasks and len(res.logs) == 2 * 2
    meta = json.loads((res.directory / "campaign.json").read_text())
    assert meta["problem"] == meta["config"]["problem"] == "arm6" and meta["query_set"] == "arm6"
    load_campaign(res.directory)  # resumable: the configuration round-trips
    con = sqlite3.connect(res.database)
    setups = {r[0] for r in con.execute("SELECT setup FROM experiments")}
    assert all("dimension 6" in s for s in setups)
    exps = con.execute("SELECT from_sector, to_sector, straight_length, model_hash, motion_validator FROM experiments").fetchall()
    hash_ = generic.model_hash(GENERIC_PROBLEMS["arm6"])
    assert all(e[:2] == (0, 0) and e[2] > 0 and e[3] == hash_ and e[4] == "discrete" for e in exps)
    rows = con.execute("SELECT plannerConfigs.name, runs.collision_checks, runs.raw_length, runs.length_dof12, "
                       "runs.length_dof34, runs.path_valid_dense, runs.reaches_goal FROM runs "
                       "JOIN plannerConfigs ON runs.plannerid = plannerConfigs.id").fetchall()
    assert {r[0] for r in rows} == {"geometric_DimensionRRT", "geometric_RRTstar", "geometric_RRTConnect",
                                    "geometric_RRTConnectSimplify"}
    assert all(r[1] > 0 for r in rows)  # the Python checker's calls, counted per run
    solved = [r for r in rows if r[2] is not None and r[6] == 1]
    assert solved and all(r[5] == 1 for r in solved)  # every exact path passes checkMotion over the whole path
    assert all(r[3] + r[4] >= r[2] - 1e-9 for r in solved)  # group lengths vs the 6-D length (triangle inequality)
    counts = con.execute("SELECT runs.iterations, progress.iterations FROM progress JOIN runs ON progress.runid = "
                         "runs.id JOIN plannerConfigs ON runs.plannerid = plannerConfigs.id "
                         "WHERE plannerConfigs.name = 'geometric_RRTConnectSimplify'").fetchall()
    assert counts and all(c == (None, None) for c in counts)  # no iteration count, not 0 iterations
    gc.collect()
