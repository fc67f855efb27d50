"""One motion (``si.checkMotion``) through the screened default validator: the plain probe first, and the middle
states first among what no ball covers; each switched off and on.

    PYTHONPATH=. .venv/bin/python experiments/colliding_motions.py                  # ~1 min (--switch probes)
    PYTHONPATH=. .venv/bin/python experiments/colliding_motions.py --switch middles
    PYTHONPATH=. .venv/bin/python experiments/colliding_motions.py --skip-rrtconnect

The default validator screens a motion with clearance balls (``tpee_ompl.model.clearance_balls``), which cannot
stop at a collision: a ball that fails says nothing of the state at its centre.  Two switches:

* ``probes`` (``PROBES`` 0 against the package's): since 2026-11-27 a single motion first checks its end state and
  its middle plainly, up to the first invalid one, as OMPL's ``DiscreteMotionValidator`` starts;
* ``middles`` (``MIDDLES_FIRST`` False against True): what no ball covers is checked in two calls, each block's
  middle state first, and a line whose middle collides skips its other states (2026-11-27, later; before, every
  uncovered state in one call).

For the wearer and the Panda shelf (if installed): 300 random valid states (numpy seed 1), motions of 1 and 0.3 rad
in random directions from them (clipped to the limits), each checked in both settings, alternating motion set by
motion set; prints the mean checks and time per colliding and per free motion (the verdicts must agree).  Then
RRTConnect's first exact path at home on both named query sets (OMPL seeded with ``--ompl-seed``), the settings
alternating query by query, 3 runs each: median time, median and mean checks.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import numpy as np
from _common import first_path_time, summary
from ompl import geometric as og
from ompl import util as ou

from tpee_ompl import WearerArm, array_to_path, make_simple_setup
from tpee_ompl.model import clearance_balls
from tpee_ompl.model.queries import load_queries


def get_argument_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(description=summary(__doc__))
    p.add_argument("--switch", choices=("probes", "middles"), default="probes", help="what is switched off and on")
    p.add_argument("--probes", type=int, default=clearance_balls.PROBES, help="probe states when on")
    p.add_argument("--ompl-seed", type=int, default=1)
    p.add_argument("--skip-rrtconnect", action="store_true")
    return p


def _robots() -> list[tuple[str, object]]:
    out: list[tuple[str, object]] = [("wearer", WearerArm())]
    try:
        from tpee_ompl import panda_shelf

        out.append(("panda_shelf", panda_shelf()))
    except ImportError:  # the optional 'robots' extra
        pass
    return out


def settings(switch: str, probes: int) -> list[tuple[str, Callable[[], None]]]:
    """(label, apply) of the two settings compared, the validator before the change first."""
    def probing(k: int) -> Callable[[], None]:
        return lambda: setattr(clearance_balls, "PROBES", k)

    def middles(on: bool) -> Callable[[], None]:
        return lambda: setattr(clearance_balls, "MIDDLES_FIRST", on)

    if switch == "probes":
        return [("probes 0", probing(0)), (f"probes {probes}", probing(probes))]
    return [("all at once", middles(False)), ("middles first", middles(True))]


def single_motions(modes: list[tuple[str, Callable[[], None]]]) -> None:
    for name, robot in _robots():
        rng = np.random.default_rng(1)
        A = rng.uniform(robot.lower, robot.upper, (4000, robot.nq))
        A = A[robot.are_valid(A)][:300]
        si = make_simple_setup(robot).getSpaceInformation()
        for length in (1.0, 0.3):
            D = rng.normal(size=A.shape)
            B = np.clip(A + length * D / np.linalg.norm(D, axis=1, keepdims=True), robot.lower, robot.upper)
            paths = [array_to_path(si, np.array([a, b])) for a, b in zip(A, B)]
            res: dict[str, tuple[list[bool], list[int], list[float]]] = {label: ([], [], []) for label, _ in modes}
            for _ in range(2):
                for label, apply in modes:
                    apply()
                    v, c, t = res[label]
                    for p in paths:
                        c0, t0 = robot.collision_checks, time.perf_counter()
                        v.append(si.checkMotion(p.getState(0), p.getState(1)))
                        t.append(time.perf_counter() - t0)
                        c.append(robot.collision_checks - c0)
            ok = np.array(res[modes[0][0]][0])
            line = f"{name:11s} {length:.1f} rad, {int((~ok).sum() / 2)} colliding / {int(ok.sum() / 2)} free:"
            for k, (v, c, t) in res.items():
                assert (np.array(v) == ok).all(), "the verdicts differ"
                c, t = np.array(c), np.array(t)
                line += (f"  {k}: {c[~ok].mean():5.1f} / {c[ok].mean():5.1f} checks, "
                         f"{1e3 * t[~ok].mean():5.2f} / {1e3 * t[ok].mean():5.2f} ms")
            print(line, flush=True)


def rrtconnect(modes: list[tuple[str, Callable[[], None]]], seed: int) -> None:
    ou.RNG.setSeed(seed)
    robot = WearerArm()
    for name in ("planning_necessary", "paper_random"):
        t: dict[str, list[float]] = {label: [] for label, _ in modes}
        c: dict[str, list[int]] = {label: [] for label, _ in modes}
        for q in load_queries(name, robot):
            ss = make_simple_setup(robot, q.start, q.goal)
            for _ in range(3):
                for k, apply in modes:
                    apply()
                    c0 = robot.collision_checks
                    dt = first_path_time(ss, og.RRTConnect(ss.getSpaceInformation()), 1.0)
                    if dt is not None:
                        t[k].append(dt)
                        c[k].append(robot.collision_checks - c0)
        print(f"{name:18s} RRTConnect median first path: "
              + ",  ".join(f"{k}: {1e3 * statistics.median(t[k]):.2f} ms ({statistics.median(c[k]):.0f} checks, mean "
                           f"{statistics.mean(c[k]):.0f}; {len(t[k])} solved)" for k in t), flush=True)


def main(argv: list[str] | None = None) -> None:
    args = get_argument_parser().parse_args(argv)
    ou.setLogLevel(ou.LOG_NONE)
    package = (clearance_balls.PROBES, clearance_balls.MIDDLES_FIRST)
    modes = settings(args.switch, args.probes)
    try:
        single_motions(modes)
        if not args.skip_rrtconnect:
            rrtconnect(modes, args.ompl_seed)
    finally:
        clearance_balls.PROBES, clearance_balls.MIDDLES_FIRST = package


if __name__ == "__main__":
    main()
