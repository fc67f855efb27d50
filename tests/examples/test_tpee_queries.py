"""tpee_ompl.examples.tpee_queries: seeded cross-sector queries and their straight motion."""

from __future__ import annotations

import numpy as np
import pytest


def test_the_straight_motion_of_a_start_off_its_row_is_refused_not_answered_for_another_motion(robot):
    from tpee_ompl.examples.tpee_queries import cross_sector_query, straight_motion_valid
    from tpee_ompl.model.sectors import posture_preset

    goal = np.r_[posture_preset(3), 0.0, 0.0]
    for start in (np.array([99.0, -99.0, 0.0, 0.0]), np.r_[np.nan, posture_preset(1)[1], 0.0, 0.0], np.zeros(3)):
        with pytest.raises(ValueError, match="start must be 4 finite numbers"):
            straight_motion_valid(robot, 1, 3, start, goal)  # was True: DOF1/DOF2 were replaced by the row's
    for kw, match in (({"tries": 0}, "tries"), ({"need_planning": "no"}, "need_planning"), ({"rng": 5}, "rng")):
        with pytest.raises(ValueError, match=match):
            cross_sector_query(robot, 1, 3, **{"rng": np.random.default_rng(1), **kw})
