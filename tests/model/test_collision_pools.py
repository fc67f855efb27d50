"""Collision pools: the tree broadphase gives the pair loop's verdicts, at the checks' margins and the screens'."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from tests.helpers.panda import needs_panda
from tpee_ompl.model import collision_pools
from tpee_ompl.model.robot_checker import RobotChecker
from tpee_ompl.model.wearer_arm import WearerArm


def _near_contact(robot: RobotChecker, n: int, seed: int) -> np.ndarray:
    """States next to contact: on straight lines from a valid to a colliding state, 1e-6..1e-2 of the line's length
    either side of where it first collides, plus 1e-4 rad of noise."""
    rng = np.random.default_rng(seed)
    Q = rng.uniform(robot.lower, robot.upper, (8 * n, robot.nq))
    ok = robot.are_valid(Q)
    free, hit = Q[ok][:n], Q[~ok][:n]
    lo, hi = np.zeros(len(free)), np.ones(len(free))
    for _ in range(30):  # bisect each line to its first contact, in batches
        mid = (lo + hi) / 2
        valid = robot.are_valid(free + mid[:, None] * (hit - free))
        lo, hi = np.where(valid, mid, lo), np.where(valid, hi, mid)
    offsets = 10.0 ** rng.uniform(-6, -2, (len(free), 4)) * rng.choice([-1, 1], (len(free), 4))
    t = np.clip(lo[:, None] + offsets, 0, 1)
    S = free[:, None, :] + t[:, :, None] * (hit - free)[:, None, :]
    S = S.reshape(-1, robot.nq) + rng.normal(0, 1e-4, (S.shape[0] * S.shape[1], robot.nq))
    return np.clip(S, robot.lower, robot.upper)


def _agree(robot: RobotChecker, twin: RobotChecker, S: np.ndarray) -> None:
    assert type(twin.pool) is pin.GeometryPool  # (the broadphase pool's bindings derive from it)
    assert type(robot.pool) is not pin.GeometryPool
    batched, loop = robot.are_valid(S), twin.are_valid(S)
    assert 0.2 < loop.mean() < 0.8  # both sides of the contacts
    assert (batched == loop).all()
    single = np.array([robot.is_valid_values(q.tolist()) for q in S[:400]])
    assert (single == loop[:400]).all()
    step = 0.01
    for radius in (4 * step, step):
        assert (robot.ball_screen().clear(S, radius) == twin.ball_screen().clear(S, radius)).all()


def test_broadphase_gives_the_pair_loops_verdicts_next_to_the_wearer():
    robot = WearerArm()
    with collision_pools.broadphase(False):
        twin = WearerArm()
    _agree(robot, twin, _near_contact(robot, 300, seed=3))


@needs_panda
def test_broadphase_gives_the_pair_loops_verdicts_on_the_panda_shelf():
    from tpee_ompl.model.robots import panda_shelf

    robot = panda_shelf()
    with collision_pools.broadphase(False):
        twin = panda_shelf()
    _agree(robot, twin, _near_contact(robot, 150, seed=4))


def test_a_model_the_broadphase_refuses_is_checked_pair_by_pair(robot, monkeypatch):
    def refuse(*args):
        raise ValueError("The bounding volume has a negative volume.")

    monkeypatch.setattr(pin, "TreeBroadPhaseManagerPool_DynamicAABBTreeCollisionManager", refuse)
    monkeypatch.setattr(pin, "TreeBroadPhaseManager_DynamicAABBTreeCollisionManager", refuse)
    gdata = robot.new_check_data()
    pool = collision_pools.new_pool(robot.model, robot.gmodel, gdata, 1)
    collides = collision_pools.single_check(robot.model, robot.model.createData(), robot.gmodel, gdata)
    assert type(pool) is pin.GeometryPool
    Q = np.random.default_rng(5).uniform(robot.lower, robot.upper, (64, robot.nq))
    expected = robot.are_valid(Q)
    assert (~np.asarray(pin.computeCollisionsInParallel(1, pool, np.ascontiguousarray(Q.T), True, False)) == expected).all()
    assert [not collides(q, True) for q in Q] == expected.tolist()


@pytest.mark.parametrize("on", [True, False])
def test_fresh_check_data_gets_a_pool_either_way(robot, on):
    for _ in range(5):  # a fresh GeometryData's placements are not initialised: Coal refused most boxes built from them
        with collision_pools.broadphase(on):
            pool = collision_pools.new_pool(robot.model, robot.gmodel, robot.new_check_data(), 2)
        assert (type(pool) is pin.GeometryPool) != on
    assert collision_pools.BROADPHASE
