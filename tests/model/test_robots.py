"""The Panda shelf and Kinova posts problems: they load, their scenes matter, and a missing extra is named."""

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
    with pytest.raises(ImportError, match=r"^the Kinova arm needs the optional 'robots' extra"):
        robots.kinova_posts()


@needs_panda
def test_the_kinova_posts_arm_plans_its_continuous_joints_as_angles_and_its_queries_are_its_own():
    from tpee_ompl.model.joint_queries import load_joint_query_set

    c = robots.kinova_posts(n_threads=1)
    assert c.nq == 6 and c.circular.tolist() == [True, False, False, True, False, True]
    assert {"post_front", "post_back"} <= set(c.geometry_names(0))
    queries, header = load_joint_query_set("kinova_posts", c)  # the packaged set was made for this model
    assert len(queries) == 30 and header["labels"] == {"across-pi": 17, "within": 13}
    assert all(c.is_valid(q.start) and c.is_valid(q.goal) for q in queries)
    assert sum(bool((np.abs(q.goal - q.start)[c.circular] > np.pi).any()) for q in queries) == 17


@needs_panda
def test_dropping_the_spheres_inside_capsules_changes_no_verdict_and_no_clearance():
    """panda_collision.urdf caps every cylinder with two spheres: as capsule end caps they are dropped."""
    import coal
    import pinocchio as pin

    c = robots.panda_shelf(n_threads=1, security_margin=0.0)
    urdf, srdf = robots.panda_files()
    full = pin.buildGeomFromUrdf(c.model, str(urdf), pin.GeometryType.COLLISION)  # spheres kept
    kept = set(c.geometry_names(0)) | {n for j in c.joint_names for n in c.geometry_names(j)}
    spheres = [g for g in full.geometryObjects if isinstance(g.geometry, coal.Sphere) and g.name not in kept
               and g.parentJoint > 0]
    assert len(spheres) >= 20  # the end caps; 4 spheres sit 0.1 mm off a tilted capsule's axis and stay
    rng = np.random.default_rng(7)
    Q = c.lower + rng.random((300, c.nq)) * (c.upper - c.lower)
    gdata = pin.GeometryData(c.gmodel)
    for q in Q:
        pin.updateGeometryPlacements(c.model, c.data, c.gmodel, gdata, q)
        for s in spheres:  # every dropped sphere is never closer to any obstacle than its link's capsule
            S = coal.Transform3s(c.data.oMi[s.parentJoint] * s.placement)
            caps = [k for k, g in enumerate(c.gmodel.geometryObjects)
                    if g.parentJoint == s.parentJoint and isinstance(g.geometry, coal.Capsule)]
            for ob in ("table", "board_1", "divider"):
                o = c.gmodel.geometryObjects[c.gmodel.getGeometryId(ob)]
                req, res = coal.DistanceRequest(), coal.DistanceResult()
                d_sphere = coal.distance(s.geometry, S, o.geometry, coal.Transform3s(o.placement), req, res)
                d_caps = min(coal.distance(c.gmodel.geometryObjects[k].geometry, coal.Transform3s(gdata.oMg[k]),
                                           o.geometry, coal.Transform3s(o.placement), req, coal.DistanceResult())
                             for k in caps)
                assert d_caps <= d_sphere + 1e-9
