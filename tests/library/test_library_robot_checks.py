"""A library, pipeline or tracker given another robot than the library's, or arguments of the wrong kind, says so at
once (a helper's tracker run died mid-stream on a library built for a robot with another helmet)."""

from __future__ import annotations

import numpy as np
import pytest

from tpee_ompl.library import LibraryDimensionRRT, PathLibrary
from tpee_ompl.library.tracker import Tracker, make_default_planner
from tpee_ompl.model.queries import load_queries
from tpee_ompl.model.wearer_arm import WearerArm
from tpee_ompl.planning.paths import motion_is_valid
from tpee_ompl.planning.setup import make_simple_setup


@pytest.fixture(scope="module")
def wider() -> WearerArm:
    """The packaged model with other collision margins (its hash is the same)."""
    return WearerArm(security_margin=0.03)


def test_a_library_is_refused_by_a_pipeline_or_default_planner_for_a_robot_with_other_margins(library, wider):
    q = load_queries("planning_necessary", wider)[0]
    ss = make_simple_setup(wider, q.start, q.goal, check_endpoints=False)
    with pytest.raises(ValueError, match="^library: its robot has other collision margins"):
        LibraryDimensionRRT(ss.getSpaceInformation(), library, 1, 2)
    with pytest.raises(ValueError, match="^library: its robot has other collision margins"):
        make_default_planner(wider, library=library)


def test_a_library_is_taken_by_another_robot_of_the_same_model_and_margins(library):
    """check_robot compared the bound methods ``pair_margins`` (not their values): a second WearerArm() of the same
    model and margins was refused as "other collision margins (security_margin 0.02 against 0.02 m)"."""
    other = WearerArm()
    assert other is not library.robot and other.model_hash == library.robot.model_hash
    library.check_robot(other)
    q = load_queries("planning_necessary", other)[0]
    LibraryDimensionRRT(make_simple_setup(other, q.start, q.goal).getSpaceInformation(), library, 1, 2)


def test_a_robot_with_other_link_margins_is_refused_naming_them(library):
    """Margins that differ only by link_margins were reported as "security_margin 0.02 against 0.02 m"."""
    other = WearerArm(link_margins={"backpack": 0.03})
    with pytest.raises(ValueError, match=r"other collision margins than this robot \(link_margins \{\} against "
                                         r"\{'backpack': 0.03\}\)"):
        library.check_robot(other)


def test_a_library_of_another_model_is_named_by_check_robot(library):
    class Other:
        model_hash = "0123456789abcdef"

    with pytest.raises(ValueError, match="^library: built for model"):
        library.check_robot(Other())


def test_a_query_whose_start_or_goal_is_not_on_its_sectors_posture_is_refused(library: PathLibrary):
    q = load_queries("planning_necessary")[0]  # 1 -> 2
    with pytest.raises(ValueError, match="^start: DOF1/DOF2 .* not sector 2's"):
        library.query(q.start, q.goal, 2, 1)  # the sectors swapped: 'failed' before, counted as a library miss
    off = q.start.copy()
    off[:2] = 0.3, 1.0
    with pytest.raises(ValueError, match="^start: "):
        library.query(off, q.goal, 1, 2)  # a 'dmp' path on a warped Table-3 row before


def test_the_tracker_names_a_robot_or_planner_of_the_wrong_kind(robot):
    with pytest.raises(ValueError, match="^planner must be a callable"):
        Tracker(robot, None)
    with pytest.raises(ValueError, match="^robot must be a WearerArm"):
        Tracker("robot", lambda s, g, i, j: None)


def test_the_default_planner_checks_its_paths_at_the_step_it_is_given(robot):
    q = load_queries("planning_necessary", robot)[3]
    plan = make_default_planner(robot, library=None, step=0.004)
    W = plan(q.start, q.goal, q.from_sector, q.to_sector)
    assert motion_is_valid(robot, W, 0.004)
