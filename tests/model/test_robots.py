"""The Panda shelf problem: it loads, its scene matters, and a missing extra is named."""

from __future__ import annotations

import builtins

import numpy as np
import pytest

from tests.helpers.panda import needs_panda
from tpee_ompl.model import robots


@needs_panda
def test_the_panda_shelf_loads_with_seven_planned_joints_and_the_shelf():
    c = robots.panda_shelf(n_threads=1)
    assert c.nq == 7 and len(robots.PANDA_GROUPS[0] + robots.PANDA_GROUPS[1]) == 7
    assert {"table", "board_1", "divider", "back"} <= set(c.geometry_names(0))
    assert c.security_margin == robots.PANDA_SECURITY_MARGIN
    assert c.max_joint_step() > 0
    q = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])  # the SRDF's default posture
    assert c.is_valid(q)
    assert robots.panda_region(c, q) is None


def test_a_missing_robots_extra_is_named_in_one_line(monkeypatch):
    real_import = builtins.__import__

    def no_erd(name, *args, **kwargs):
        if name == "example_robot_data":
            raise ImportError("No module named 'example_robot_data'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_erd)
    with pytest.raises(ImportError, match=r"^the Panda needs the optional 'robots' extra: pip install 'tpee-ompl\[robots\]'$"):
        robots.panda_shelf()
