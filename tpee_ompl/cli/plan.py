"""``tpee-ompl plan|aim|track``: plan one cross-sector motion, aim at a target, track a scripted target."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..bench.config import CLI_PLANNER_NAMES
from ..library import dimension_rrt_planner
from ..model.pointing import aim
from ._common import (
    CliError,
    add_force_arg,
    add_model_args,
    angle,
    argument,
    check_input_file,
    check_library_model,
    check_model_args,
    check_output,
    count,
    default_of,
    finite,
    index,
    load_robot,
    nonempty,
    on_postures,
    positive_float,
    positive_int,
    seconds,
    sector,
    seed,
)

if TYPE_CHECKING:
    from ..model.wearer_arm import WearerArm

__all__ = ["MAX_TRACK_SAMPLES", "PLANNERS", "add_plan_args", "check_plan_args", "cmd_aim", "cmd_plan", "cmd_track",
           "plan_motion", "register"]

MAX_TRACK_SAMPLES = 100_000
"""Most target samples ``track`` accepts (``--duration`` x ``--rate``): more is refused before any work."""

DEFAULT_STALL = 1000
"""``plan --stall``: samples without a shorter path after which dimension-RRT counts as converged."""

_STALL_PLANNERS = ("dimension-rrt", "library")
"""The ``--planner`` choices that read ``--stall`` (the default planner is one of them)."""

PLANNERS = CLI_PLANNER_NAMES
"""``--planner`` choices: CLI name -> planner class name (``ompl.geometric.<name>``; DimensionRRT is this package's)."""


# ---------------------------------------------------------------------------------------- plan
def _make_planner(name: str, si: Any, from_sector: int, to_sector: int, samples: int | None, seed: int,
                  stall: int | None = None, library: str | None = None):
    """Planner instance (built like the benchmark's, :mod:`tpee_ompl.bench.planners`) and a
    termination-condition factory for a sample cap, if any."""
    from ompl import base as ob

    from ..bench.config import NOT_ITERATION_CAPPED
    from ..bench.planners import PlannerContext, planner_factory

    if samples is not None and PLANNERS[name] in NOT_ITERATION_CAPPED:  # said before the planner is built (an
        # AORRTC freed unsolved crashed the process)
        raise CliError(f"--samples needs a planner that counts iterations; {name} does not (use --time)")
    capped_by_samples = name in ("dimension-rrt", "library")  # our planners take the cap themselves
    ctx = PlannerContext(query={"from_sector": from_sector, "to_sector": to_sector},
                         max_samples=samples if capped_by_samples else None, seed=seed, stall_samples=stall or None,
                         library=library)
    planner = planner_factory(PLANNERS[name])(si, ctx)
    if samples is None or capped_by_samples:
        return planner, None
    if not hasattr(planner, "numIterations"):
        raise CliError(f"--samples needs a planner that counts iterations; {name} does not (use --time)")
    return planner, lambda: ob.PlannerTerminationCondition(lambda: planner.numIterations() >= samples)


def check_plan_args(args: argparse.Namespace) -> None:
    """Usage checks of one planning problem's arguments that argparse cannot do alone (before any work)."""
    if (args.start is None) != (args.goal is None):
        raise CliError("give both --start and --goal, or neither")
    if args.from_sector == args.to_sector:
        raise CliError(f"--from and --to are both sector {args.from_sector}: a cross-sector motion needs two sectors")
    check_model_args(args)
    if args.library is not None:
        if args.planner not in (None, "library"):
            raise CliError(f"--library is read by --planner library, not {args.planner}")
        args.planner = "library"
        check_input_file(args.library, "--library", "path library")
    if "--stall" in getattr(args, "plan_options_given", ()) and args.planner not in (None, *_STALL_PLANNERS):
        raise CliError(f"--stall is read by --planner {' and '.join(_STALL_PLANNERS)}, not {args.planner}")


def _default_planner(args: argparse.Namespace, robot: WearerArm) -> str:
    """--planner, or by default ``library`` when a library for the model is at hand (--library, or the packaged one
    for its model), else ``dimension-rrt``; --planner library without one for the model is a usage error."""
    if args.library is not None:
        check_library_model(args.library, robot)
        return "library"
    if args.planner not in (None, "library"):
        return args.planner
    return "library" if _packaged_library(robot, required=args.planner == "library") else "dimension-rrt"


def _packaged_library(robot: WearerArm, required: bool) -> Path | None:
    """The packaged library when it was built for the model (a damaged one raises); with ``required``
    (``--planner library``) a usage error when it was not."""
    from ..library.storage import packaged_library_for

    path = packaged_library_for(robot)
    if path is None and required:
        raise CliError("--planner library: the packaged path library was built for the packaged model, not this "
                       "--urdf/--srdf; give --library FILE built for it ('tpee-ompl library build --urdf U --srdf S "
                       "--library FILE')")
    return path


def _start_and_goal(args: argparse.Namespace, robot: WearerArm) -> tuple[np.ndarray, np.ndarray, str | None]:
    """--start/--goal, or the --query-index'th query of --queries for the sector pair; and the query id.

    The query set must have been made for ``robot`` (its ``model_hash``).
    """
    if args.start is not None and args.goal is not None:
        return np.array(args.start), np.array(args.goal), None
    from ..model.queries import QuerySetError, load_queries

    try:
        queries = load_queries(args.queries, robot)
    except OSError as exc:  # missing, a folder, a pipe, not readable
        raise CliError(f"--queries: {exc}") from None
    except QuerySetError as exc:
        if getattr(args, "urdf", None) and "made for model_hash" in str(exc):  # the packaged sets are the packaged model's
            raise CliError(f"--queries {args.queries}: {exc}; with --urdf give --start and --goal, or --queries FILE "
                           "made for that model") from None
        raise
    pair = (args.from_sector, args.to_sector)
    matching = [q for q in queries if (q.from_sector, q.to_sector) == pair]
    if not matching:
        raise CliError(f"--queries {args.queries}: no query from sector {args.from_sector} to {args.to_sector}")
    if args.query_index >= len(matching):
        raise CliError(f"--query-index {args.query_index}: the set has {len(matching)} queries for that pair "
                       f"(0..{len(matching) - 1})")
    q = matching[args.query_index]
    return np.asarray(q.start), np.asarray(q.goal), q.id


def plan_motion(args: argparse.Namespace) -> tuple[dict, WearerArm]:
    """Plan the motion the arguments describe; returns a JSON-ready result and the robot it used."""
    from ompl import base as ob
    from ompl import util as ou

    from ..planning.paths import path_passes_motion_checks, path_to_array
    from ..planning.planner_base import status_text
    from ..planning.setup import make_simple_setup, seed_ompl

    check_plan_args(args)
    ou.setLogLevel(ou.LOG_WARN)
    seed_ompl(args.seed)
    robot = load_robot(args)
    args.planner = _default_planner(args, robot)
    start, goal, qid = _start_and_goal(args, robot)
    if qid is None:
        start, goal, off_posture = on_postures(start, goal, args.from_sector, args.to_sector)
        with argument("--start/--goal"):
            ss = make_simple_setup(robot, start, goal)
        if off_posture:
            raise CliError(off_posture)
    else:
        ss = make_simple_setup(robot, start, goal)
    si = ss.getSpaceInformation()
    planner, ptc_factory = _make_planner(args.planner, si, args.from_sector, args.to_sector, args.samples, args.seed,
                                         args.stall, args.library)
    ss.setPlanner(planner)
    checks0 = robot.collision_checks
    if ptc_factory is not None:
        status = ss.solve(ob.plannerOrTerminationCondition(ptc_factory(), ob.timedPlannerTerminationCondition(args.time)))
    else:
        status = ss.solve(args.time)
    result: dict = {"planner": args.planner, "from_sector": args.from_sector, "to_sector": args.to_sector,
                    "query_id": qid, "status": status_text(status), "exact": bool(ss.haveExactSolutionPath()),
                    "time_s": ss.getLastPlanComputationTime(), "collision_checks": robot.collision_checks - checks0,
                    "samples": _samples_drawn(planner)}
    if ss.haveSolutionPath():
        path = ss.getSolutionPath()
        result["valid"] = path_passes_motion_checks(si, path)
        result["length_rad"] = float(path.length())
        result["path"] = path_to_array(path, robot.nq).round(6).tolist()
    return result, robot


def _samples_drawn(planner: Any) -> int | None:
    """Samples (iterations) the planner drew in its solve: ours report them, OMPL's count iterations; else None."""
    if hasattr(planner, "last_run_stats"):
        return planner.last_run_stats().get("samples")
    return int(planner.numIterations()) if hasattr(planner, "numIterations") else None


def cmd_plan(args: argparse.Namespace) -> int:
    """Plan one cross-sector motion and print the path, its validity and length."""
    result, _ = plan_motion(args)
    if args.json:
        print(json.dumps(result))
    else:
        drawn = "" if result["samples"] is None else f", {result['samples']} samples"
        print(f"{args.planner}: sector {args.from_sector} -> {args.to_sector}, status {result['status']}, "
              f"{result['time_s']:.3f} s{drawn}, {result['collision_checks']} collision checks")
        if args.samples is not None and result["samples"] is not None and result["samples"] < args.samples \
                and result["time_s"] >= 0.99 * args.time:
            print(f"stopped by --time {args.time:g} before --samples {args.samples}")
        if "path" in result:
            print(f"valid (checkMotion on every segment): {result['valid']}, length {result['length_rad']:.4f} rad, "
                  f"{len(result['path'])} waypoints (DOF1..DOF4, rad):")
            for w in result["path"]:
                print("  " + " ".join(f"{v:+.4f}" for v in w))
    return 0 if result["exact"] else 1


class _StoreNoted(argparse._StoreAction):  # noqa: SLF001 (argparse's plain "store", which it extends)
    """argparse's "store" that also notes the option in ``args.plan_options_given``: ``animate --path`` plans
    nothing and refuses each one given, also when given at its default value (``--from 1``)."""

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace, values: Any,
                 option_string: str | None = None) -> None:
        super().__call__(parser, namespace, values, option_string)
        given = list(getattr(namespace, "plan_options_given", None) or [])  # a new list: the default one stays empty
        if self.option_strings[0] not in given:
            given.append(self.option_strings[0])
        namespace.plan_options_given = given


def add_plan_args(p: argparse.ArgumentParser, required: bool = False) -> None:
    """The arguments of one planning problem (sectors, planner, limits, start/goal or a stored query); the ones given
    are listed in ``args.plan_options_given``."""
    p.add_argument("--from", action=_StoreNoted, dest="from_sector", type=sector, required=required, default=1,
                   help="start posture sector (1-4)")
    p.add_argument("--to", action=_StoreNoted, dest="to_sector", type=sector, required=required, default=4,
                   help="goal posture sector (1-4)")
    p.add_argument("--planner", action=_StoreNoted, choices=tuple(PLANNERS), default=None,
                   help="library: the DMP path library's validated path, refined by dimension-RRT (default when a "
                        "library for the model is at hand, else dimension-rrt); rrtconnect-simplify: RRTConnect + "
                        "OMPL's PathSimplifier; the others: OMPL's planners")
    p.add_argument("--library", action=_StoreNoted, type=nonempty, default=None, metavar="FILE",
                   help="path library of --planner library (default: the packaged one, for the packaged model; "
                        "'tpee-ompl library build --urdf U --srdf S --library FILE' builds one for another)")
    p.add_argument("--time", action=_StoreNoted, type=seconds, default=5.0,
                   help="time limit in seconds, at most a day (default 5)")
    p.add_argument("--samples", action=_StoreNoted, type=positive_int, default=None, help="sample / iteration cap")
    p.add_argument("--stall", action=_StoreNoted, type=count, default=DEFAULT_STALL,
                   help="library / dimension-rrt: stop after this many samples without a shorter path, before --time "
                        f"(0: use the whole --time; default {DEFAULT_STALL})")
    p.add_argument("--seed", action=_StoreNoted, type=seed, default=1,
                   help="OMPL / planner seed, 1..2^32-1 (default 1)")
    p.add_argument("--queries", action=_StoreNoted, type=nonempty, default="planning_necessary",
                   help="query set name or JSON file (made for the loaded model: its model_hash must match)")
    p.add_argument("--query-index", action=_StoreNoted, type=index, default=0,
                   help="which query of that pair, from 0 (default 0)")
    p.add_argument("--start", action=_StoreNoted, type=finite, nargs=4, default=None, metavar="Q",
                   help="start DOF1..DOF4 (rad)")
    p.add_argument("--goal", action=_StoreNoted, type=finite, nargs=4, default=None, metavar="Q",
                   help="goal DOF1..DOF4 (rad)")
    p.set_defaults(plan_options_given=[])
    add_model_args(p)


# ---------------------------------------------------------------------------------------- aim / track
def cmd_aim(args: argparse.Namespace) -> int:
    """Closed-form aiming IK for one target (eqs. 1-11) with the collision and line-of-sight verdict."""
    from ..model.pointing import PointingGeometry, aim_errors, check_target
    from ..model.sectors import select_sector

    robot = load_robot(args)
    geometry = PointingGeometry.from_robot(robot)  # the loaded model's (--urdf), not the packaged one's
    with argument("--target"):
        target = check_target(np.array(args.target), robot)
    with argument("--target" if args.sector is None else f"--target with --sector {args.sector}"):
        sector_ = args.sector if args.sector is not None else select_sector(target, origin=geometry.pivot)
        q = aim(target, sector_, geometry=geometry, pan_reference=args.pan_reference)  # may be out of the arm's reach
    perp, _, ang = aim_errors(robot, q, target)
    result = {"target": target.tolist(), "sector": sector_, "q_rad": q.round(9).tolist(),
              "q_deg": np.degrees(q).round(4).tolist(), "collision_free": robot.is_valid(q),
              "line_of_sight_clear": robot.line_of_sight_clear(q, target), "aim_error_m": perp, "aim_error_rad": ang}
    if args.json:
        print(json.dumps(result))
    else:
        print(f"sector {sector_}: DOF1..DOF4 = {' '.join(f'{v:+.6f}' for v in q)} rad "
              f"({' '.join(f'{v:+.2f}' for v in np.degrees(q))} deg)")
        print(f"collision-free: {result['collision_free']}, line of sight clear: {result['line_of_sight_clear']}, "
              f"aim error {perp:.1e} m")
    return 0 if result["collision_free"] and result["line_of_sight_clear"] else 1


def _scripted_targets(name: str, duration: float, rate: float) -> list[tuple]:
    """Target streams for `track`: a circle around the wearer, boundary jitter, sector jumps."""
    t = np.arange(0.0, duration, 1.0 / rate)
    if name == "circle":
        az = 2 * np.pi * t / duration
        pts = np.c_[5 * np.cos(az), 5 * np.sin(az), 1.5 + 1.0 * np.sin(3 * az)]
        return [(ti, p) for ti, p in zip(t, pts)]
    if name == "jitter":
        rng = np.random.default_rng(0)
        az = np.radians(90.0 + rng.uniform(-4.0, 4.0, size=t.size))  # the 2/3 posture boundary, to the left
        pts = np.c_[6 * np.cos(az) - 0.3, 6 * np.sin(az), np.full(t.size, 2.0)]
        return [(ti, p) for ti, p in zip(t, pts)]
    if name == "jump":
        spots = [np.array(v) for v in ((6.0, 3.0, 2.0), (-2.0, -6.0, 1.0), (-5.0, 4.0, 2.5), (6.0, -3.0, 1.5))]
        spot = [int(k * len(spots) / t.size) for k in range(t.size)]
        return [(ti, spots[spot[k]], k > 0 and spot[k] != spot[k - 1]) for k, ti in enumerate(t)]
    raise CliError(f"unknown script {name!r}")


def cmd_track(args: argparse.Namespace) -> int:
    """Run the Fig. 10 tracking strategy on a scripted target stream and report its events."""
    from ..library.tracker import MAX_TIME, Tracker, make_default_planner
    from ..progress import progress_bar

    if not args.duration <= MAX_TIME:  # the tracker takes sample times within +/- MAX_TIME
        raise CliError(f"--duration {args.duration:g} s is beyond the tracker's {MAX_TIME:g} s")
    n_samples = args.duration * args.rate
    if not n_samples <= MAX_TRACK_SAMPLES:
        raise CliError(f"--duration {args.duration:g} x --rate {args.rate:g} = {n_samples:.3g} target samples; "
                       f"at most {MAX_TRACK_SAMPLES} are tracked")
    if args.output:
        check_output(args.output, "--output", args.force)
    if args.library is not None:
        if args.planner not in ("default", "library"):
            raise CliError(f"--library is read by --planner default and library, not {args.planner}")
        check_input_file(args.library, "--library", "path library")
    if args.samples is not None and args.planner == "default":
        raise CliError("--samples caps dimension-RRT in --planner dimension-rrt and library; the default planner "
                       "refines by time")
    samples = default_of(dimension_rrt_planner, "max_samples") if args.samples is None else args.samples
    robot = load_robot(args)
    if args.library is not None:  # (read by the default and library planners only: refused above for the others)
        check_library_model(args.library, robot)
    else:  # the packaged library, when it was built for this model
        packaged = _packaged_library(robot, required=args.planner == "library")
        args.library = None if packaged is None else str(packaged)
    if args.planner == "dimension-rrt":
        plan = dimension_rrt_planner(robot, max_samples=samples, seed=args.seed)

        def planner(start: np.ndarray, goal: np.ndarray, i: int, j: int) -> np.ndarray:
            path = plan(start, goal, i, j) if i != j else None
            if path is None:
                raise RuntimeError(f"dimension-RRT found no path {i}->{j}")
            return path
    elif args.planner == "library":
        from ..library import PathLibrary

        lib = PathLibrary.load(args.library, robot,
                               plan=dimension_rrt_planner(robot, max_samples=samples, seed=args.seed))
        # same-sector re-aims have no demonstrations: the default planner's straight motion or RRTConnect, seeded
        planner = lib.as_planner(same_sector=make_default_planner(robot, seed=args.seed, library=None))
    else:
        planner = make_default_planner(robot, seed=args.seed, library=args.library)
    stream = _scripted_targets(args.script, args.duration, args.rate)
    # on stderr, only when the run lasts more than 2 s (a long --duration x --rate ran a minute without a word)
    result = Tracker(robot, planner).run(progress_bar(stream, desc="track", unit="sample", delay=2.0,
                                                      enabled=not args.no_progress))
    kinds = ("aim", "cross-sector", "blind-area", "unreachable")
    summary = {k: result.count(k) for k in kinds}
    if args.output:
        from ..files import atomic_path

        header = "t,dof1,dof2,dof3,dof4,sector"
        with atomic_path(args.output, force=args.force) as tmp:
            np.savetxt(tmp, np.c_[result.times, result.configurations, result.sectors], delimiter=",",
                       header=header, comments="", fmt=["%.17g"] * 5 + ["%d"])
    if args.json:
        print(json.dumps({"script": args.script, "samples": len(stream), "trajectory_points": len(result.times),
                          "events": summary, "output": args.output}))
    else:
        print(f"{args.script}: {len(stream)} target samples -> {len(result.times)} trajectory points; "
              + ", ".join(f"{k} {v}" for k, v in summary.items()))
        if args.output:
            print(f"wrote {args.output}")
    return 0


# ---------------------------------------------------------------------------------------- parsers
def register(sub: argparse._SubParsersAction, fmt: type) -> None:
    """Add the ``plan``, ``aim`` and ``track`` subcommands."""
    p = sub.add_parser("plan", help="plan one cross-sector motion", formatter_class=fmt,
                       description="Plan a cross-sector motion between the first stored query of a sector pair "
                                   "(or --start/--goal).\n\nexample:\n"
                                   "  tpee-ompl plan --from 1 --to 4 --planner dimension-rrt\n"
                                   "  tpee-ompl plan --from 2 --to 3 --planner rrtstar --samples 1000 --json")
    add_plan_args(p, required=True)
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p.set_defaults(func=cmd_plan)

    p = sub.add_parser("aim", help="aiming IK for a target", formatter_class=fmt,
                       description="Closed-form aiming IK (paper eqs. 1-11).\n\nexample:\n"
                                   "  tpee-ompl aim --target 5 2 1.5\n  tpee-ompl aim --target -4 -3 1 --sector 1 --json")
    p.add_argument("--target", type=finite, nargs=3, required=True, metavar=("X", "Y", "Z"), help="metres, world frame")
    p.add_argument("--sector", type=sector, default=None, help="posture sector (default: chosen from the target)")
    p.add_argument("--pan-reference", type=angle, default=default_of(aim, "pan_reference"),
                   help="pan angle the smaller rotation is measured from")
    p.add_argument("--json", action="store_true")
    add_model_args(p)
    p.set_defaults(func=cmd_aim)

    p = sub.add_parser("track", help="run the tracking strategy (Fig. 10) on a scripted target", formatter_class=fmt,
                       description="Track a scripted target: re-aim inside a pointing sector, plan cross-sector motions "
                                   "when it leaves.  -o writes the trajectory as CSV, columns t,dof1..dof4,sector: one "
                                   "row per configuration the arm reaches, t its arrival (s; samples that come while the "
                                   "arm moves share it), sector 0 on the waypoints of a cross-sector motion.\n\n"
                                   "example:\n  tpee-ompl track --script circle\n"
                                   "  tpee-ompl track --script jump --planner dimension-rrt -o traj.csv")
    p.add_argument("--script", choices=("circle", "jitter", "jump"), default="circle")
    p.add_argument("--planner", choices=("default", "dimension-rrt", "library"), default="default",
                   help="cross-sector planner: default (LibraryDimensionRRT for 0.05 s, then Table 3's straight "
                        "motion, else RRTConnect), dimension-rrt, library (PathLibrary.query alone)")
    p.add_argument("--library", type=nonempty, default=None, metavar="FILE",
                   help="path library file (default and library planners; default: the packaged one when it was "
                        "built for the model, else none: the default planner then plans without it)")
    p.add_argument("--samples", type=positive_int, default=None,
                   help="dimension-RRT sample cap (--planner dimension-rrt and library; default: "
                        f"{default_of(dimension_rrt_planner, 'max_samples')})")
    p.add_argument("--duration", type=positive_float, default=20.0, help=f"seconds of target motion (duration x rate <= {MAX_TRACK_SAMPLES})")
    p.add_argument("--rate", type=positive_float, default=10.0, help="target samples per second")
    p.add_argument("--seed", type=seed, default=1, help="OMPL / planner seed, 1..2^32-1 (default 1)")
    p.add_argument("--json", action="store_true")
    p.add_argument("--no-progress", action="store_true",
                   help="no progress bar (shown on stderr when the run lasts more than 2 s)")
    p.add_argument("-o", "--output", type=nonempty, help="write the trajectory as CSV (a new file; --force to replace one)")
    add_force_arg(p)
    add_model_args(p)
    p.set_defaults(func=cmd_track)
