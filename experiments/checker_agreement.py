"""Figures for the generic checker: (a) batched verdicts vs Coal's own per-pair distances on random
Panda configurations at margin 0, (b) batched cost per configuration vs serial
``pin.computeCollisions`` (single thread, same pairs), side by side, (c) the wearer vs the oracle.

    PYTHONPATH=. python experiments/checker_agreement.py [-n 10000]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import coal
from _common import summary
import numpy as np
import pinocchio as pin

from tpee_ompl.model.robots import panda_shelf
from tpee_ompl.model.wearer_arm import WearerArm

ORACLE = Path(__file__).resolve().parents[1] / "tests/model/data/wearer_oracle.npz"


def coal_collides(c, q: np.ndarray) -> bool:
    """True if any checked pair has Coal distance <= 0 at q (FK by Pinocchio, narrowphase by Coal)."""
    pin.framesForwardKinematics(c.model, c.data, q)
    pin.updateGeometryPlacements(c.model, c.data, c.gmodel, c.gdata)
    g, req, res = c.gmodel.geometryObjects, coal.DistanceRequest(), coal.DistanceResult()
    for cp in c.gmodel.collisionPairs:
        res.clear()
        if coal.distance(g[cp.first].geometry, coal.Transform3s(c.gdata.oMg[cp.first]), g[cp.second].geometry,
                         coal.Transform3s(c.gdata.oMg[cp.second]), req, res) <= 0:
            return True
    return False


def main() -> None:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("-n", type=int, default=10000)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    c = panda_shelf(n_threads=1, security_margin=0.0)
    Q = c.lower + rng.random((args.n, c.nq)) * (c.upper - c.lower)
    batched = c.are_valid(Q)
    coal_valid = np.array([not coal_collides(c, q) for q in Q])
    dis = int((batched != coal_valid).sum())
    print(f"(a) {args.n} Panda configurations, margin 0: {int(batched.sum())} valid; disagreements with Coal: {dis}")

    for threads in (1, 2):
        c2 = panda_shelf(n_threads=threads, security_margin=0.0)
        rows = {"batched": [], "serial": []}
        for _ in range(5):  # interleaved rounds, medians: the machine is shared
            t = time.perf_counter()
            c2.are_valid(Q)
            rows["batched"].append((time.perf_counter() - t) / len(Q))
            t = time.perf_counter()
            for q in Q:
                pin.computeCollisions(c2.model, c2.data, c2.gmodel, c2.gdata, q, True)
            rows["serial"].append((time.perf_counter() - t) / len(Q))
        b, s = np.median(rows["batched"]) * 1e6, np.median(rows["serial"]) * 1e6
        print(f"(b) {threads} thread(s): batched {b:.1f} us/config, serial computeCollisions loop {s:.1f} us/config, "
              f"ratio {b / s:.2f}")

    with np.load(ORACLE) as o:
        w = WearerArm(n_threads=2)
        same = (w.are_valid(o["Q"]) == o["default_are_valid"]).all()
        inside = o["Q"][o["within"]][:500]
        clear = np.array([w.clearance(q) for q in inside])
        print(f"(c) wearer vs oracle: verdicts identical {bool(same)}, clearances bit-identical "
              f"{bool(np.array_equal(clear, o['default_clearance']))}, lever arms identical "
              f"{bool(np.array_equal(w.lever_arms(), o['default_lever_arms']))}")


if __name__ == "__main__":
    main()
