"""Where a robot's collision checks run: Pinocchio's tree broadphase, or every checked pair in turn.

A ``GeometryPool`` narrow-phases every active pair of every configuration (Coal's exact test of the two shapes,
however far apart they are).  Pinocchio's *tree broadphase* keeps one Coal
``DynamicAABBTreeCollisionManager`` per joint subtree, each object's box inflated by the largest security
margin of its pairs, and narrow-phases only the active pairs whose boxes overlap, with the same requests
(margins, contacts) as the pair loop: the same verdicts, compared in the tests on random and near-contact
configurations of the wearer and the Panda, at the checks' margins and at the inflated margins of the
clearance balls.  Measured side by side (``experiments/collision_throughput.py --robots wearer panda kinova``, the
README's table): a collision-free configuration's batched check 1.6x faster on the wearer, 1.7x on the Panda
shelf and 7x on the Kinova arm among posts; a single check 1.2x / 1.6x / 3.7x.

:data:`BROADPHASE` switches it off (every pair in turn, as before 2026-11-28) for side-by-side runs
(:func:`broadphase` sets it for what is built inside a ``with`` block).  A
model the broadphase refuses (Coal raises on a bounding box of negative volume, as it does for a fresh
``GeometryData`` whose placements were never computed: :func:`_place` computes them first) falls back to the
pair loop, with the same verdicts.
"""

from __future__ import annotations

import contextlib
import functools
import logging
from collections.abc import Callable, Iterator

import numpy as np
import pinocchio as pin

__all__ = ["BROADPHASE", "CollisionPool", "broadphase", "new_pool", "single_check"]

log = logging.getLogger(__name__)

BROADPHASE = True
"""Batched and single checks through the tree broadphase (False: every active pair narrow-phased; a switch for
``experiments/collision_throughput.py --pair-loop`` and scratch A/B runs)."""

CollisionPool = pin.GeometryPool | pin.TreeBroadPhaseManagerPool_DynamicAABBTreeCollisionManager
"""What ``pin.computeCollisionsInParallel`` is given: a pool of per-thread collision data."""


@contextlib.contextmanager
def broadphase(on: bool) -> Iterator[None]:
    """Checkers, pools and ball screens built inside take the broadphase (``on``) or the pair loop; :data:`BROADPHASE`
    is restored after (for side-by-side runs and tests: the same verdicts either way)."""
    global BROADPHASE
    saved, BROADPHASE = BROADPHASE, bool(on)
    try:
        yield
    finally:
        BROADPHASE = saved


def new_pool(model: pin.Model, gmodel: pin.GeometryModel, gdata: pin.GeometryData, n_threads: int) -> CollisionPool:
    """A pool of ``n_threads`` copies of ``gdata`` (its margins, requests and active pairs) for batched checks:
    the tree broadphase when :data:`BROADPHASE` and Coal accepts the model, else a ``GeometryPool``."""
    if BROADPHASE:
        _place(model, gmodel, gdata)
        try:
            pool = pin.TreeBroadPhaseManagerPool_DynamicAABBTreeCollisionManager(model, gmodel, n_threads)
            pool.update(gdata)
            return pool
        except (ValueError, RuntimeError) as exc:  # Coal's refusal of a bounding box
            log.debug("tree broadphase refused (%s); checking every pair in turn", str(exc).splitlines()[-1])
    pool = pin.GeometryPool(model, gmodel, n_threads)
    pool.update(gdata)
    return pool


def single_check(model: pin.Model, data: pin.Data, gmodel: pin.GeometryModel,
                 gdata: pin.GeometryData) -> Callable[[np.ndarray, bool], bool]:
    """``f(q, stop_at_first)``: True when configuration q collides, with ``gdata``'s margins and active pairs
    (forward kinematics and placements included, as ``pin.computeCollisions``); ``gdata`` must outlive f."""
    if BROADPHASE:
        _place(model, gmodel, gdata)
        try:
            manager = pin.TreeBroadPhaseManager_DynamicAABBTreeCollisionManager(model, gmodel, gdata)
            return functools.partial(pin.computeCollisions, model, data, manager)
        except (ValueError, RuntimeError) as exc:
            log.debug("tree broadphase refused (%s); checking every pair in turn", str(exc).splitlines()[-1])
    return functools.partial(pin.computeCollisions, model, data, gmodel, gdata)


def _place(model: pin.Model, gmodel: pin.GeometryModel, gdata: pin.GeometryData) -> None:
    """Give a fresh ``gdata`` placements (at the neutral configuration) before a broadphase manager boxes its
    objects: a new ``GeometryData``'s are not all initialised, and Coal refuses the boxes built from them
    (28 of 30 pools on the wearer)."""
    pin.updateGeometryPlacements(model, model.createData(), gmodel, gdata, pin.neutral(model))
