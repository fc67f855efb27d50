"""The ``tpee-ompl`` command line: plan, aim, bench, library, track, show, animate, view.

Every subcommand is one function; errors from bad input are printed as one line on stderr with
exit code 2, never a traceback.
"""

from __future__ import annotations

import argparse
import gc
import json
import logging
import math
import sys
from collections.abc import Callable, Sequence

import numpy as np

from ..resources import default_library_path

__all__ = ["get_argument_parser", "main", "PLANNERS", "CliError"]

log = logging.getLogger(__name__)


class CliError(Exception):
    """A user-facing error: printed as one line, exit code 2."""


PLANNERS = ("dimension-rrt", "rrtstar", "informedrrtstar", "rrtconnect", "aorrtc", "bitstar")


def _finite(text: str) -> float:
    v = float(text)
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"not a finite number: {text}")
    return v


def _positive_int(text: str) -> int:
    v = int(text)
    if v <= 0:
        raise argparse.ArgumentTypeError(f"must be a positive integer: {text}")
    return v


def _positive_float(text: str) -> float:
    v = _finite(text)
    if v <= 0:
        raise argparse.ArgumentTypeError(f"must be > 0: {text}")
    return v


def _sector(text: str) -> int:
    from ..model.sectors import check_sector

    try:
        return check_sector(int(text))
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


# ---------------------------------------------------------------------------------------- plan
def _make_planner(name: str, si, from_sector: int, to_sector: int, samples: int | None, seed: int):
    """Planner instance and a termination-condition factory for it."""
    from ompl import base as ob
    from ompl import geometric as og

    if name == "dimension-rrt":
        from ..planning.tpee import tpee_dimension_rrt

        planner = tpee_dimension_rrt(si, from_sector, to_sector, max_samples=samples, seed=seed)
        return planner, None
    cls = {
        "rrtstar": og.RRTstar,
        "informedrrtstar": og.InformedRRTstar,
        "rrtconnect": og.RRTConnect,
        "aorrtc": og.AORRTC,
        "bitstar": og.BITstar,
    }[name]
    planner = cls(si)
    if samples is not None:
        if not hasattr(planner, "numIterations"):
            raise CliError(f"--samples needs a planner that counts iterations; {name} does not (use --time)")
        return planner, lambda: ob.PlannerTerminationCondition(lambda: planner.numIterations() >= samples)
    return planner, None


def _load_robot(args: argparse.Namespace):
    from ..model.wearer_arm import WearerArm

    if getattr(args, "srdf", None) and not getattr(args, "urdf", None):
        raise CliError("--srdf needs --urdf")
    return WearerArm(args.urdf, args.srdf) if getattr(args, "urdf", None) else WearerArm()


def _plan(args: argparse.Namespace) -> dict:
    """Plan the motion the arguments describe; returns a JSON-ready result."""
    from ompl import base as ob
    from ompl import util as ou

    from ..planning.setup import make_simple_setup
    from ..planning.paths import path_to_array

    ou.setLogLevel(ou.LOG_WARN)
    if args.seed is not None:
        ou.RNG.setSeed(args.seed)
    robot = _load_robot(args)
    if args.start is not None and args.goal is not None:
        start, goal, qid = np.array(args.start), np.array(args.goal), None
    elif args.start is None and args.goal is None:
        from ..model.queries import load_queries

        matching = [q for q in load_queries(args.queries) if (q.from_sector, q.to_sector) == (args.from_sector, args.to_sector)]
        if not matching:
            raise CliError(f"query set {args.queries!r} has no query from sector {args.from_sector} to {args.to_sector}")
        if args.query_index >= len(matching):
            raise CliError(f"--query-index {args.query_index}: the set has {len(matching)} queries for that pair")
        q = matching[args.query_index]
        start, goal, qid = np.asarray(q.start), np.asarray(q.goal), q.id
    else:
        raise CliError("give both --start and --goal, or neither")
    ss = make_simple_setup(robot, start, goal)
    si = ss.getSpaceInformation()
    planner, ptc_factory = _make_planner(args.planner, si, args.from_sector, args.to_sector, args.samples, args.seed or 0)
    ss.setPlanner(planner)
    checks0 = robot.collision_checks
    if ptc_factory is not None:
        status = ss.solve(ob.plannerOrTerminationCondition(ptc_factory(), ob.timedPlannerTerminationCondition(args.time)))
    else:
        status = ss.solve(args.time)
    exact = bool(ss.haveExactSolutionPath())
    result: dict = {"planner": args.planner, "from_sector": args.from_sector, "to_sector": args.to_sector,
                    "query_id": qid, "status": str(status), "exact": exact,
                    "time_s": ss.getLastPlanComputationTime(), "collision_checks": robot.collision_checks - checks0}
    if ss.haveSolutionPath():
        path = ss.getSolutionPath()
        states = path.getStates()
        result["valid"] = bool(all(si.checkMotion(a, b) for a, b in zip(states[:-1], states[1:])))
        result["length_rad"] = float(path.length())
        result["path"] = path_to_array(path, robot.nq).round(6).tolist()
    result["_robot"] = robot
    return result


def cmd_plan(args: argparse.Namespace) -> int:
    """Plan one cross-sector motion and print the path, its validity and length."""
    result = _plan(args)
    result.pop("_robot")
    exact = result["exact"]
    if args.json:
        print(json.dumps(result))
    else:
        print(f"{args.planner}: sector {args.from_sector} -> {args.to_sector}, status {result['status']}, "
              f"{result['time_s']:.3f} s, {result['collision_checks']} collision checks")
        if "path" in result:
            print(f"valid (checkMotion on every segment): {result['valid']}, length {result['length_rad']:.4f} rad, "
                  f"{len(result['path'])} waypoints (DOF1..DOF4, rad):")
            for w in result["path"]:
                print("  " + " ".join(f"{v:+.4f}" for v in w))
    return 0 if exact else 1


# ---------------------------------------------------------------------------------------- aim / track
def cmd_aim(args: argparse.Namespace) -> int:
    """Closed-form aiming IK for one target (eqs. 1-11) with the collision and line-of-sight verdict."""
    from ..model.pointing import aim, aim_errors, check_target
    from ..model.sectors import select_sector

    robot = _load_robot(args)
    target = check_target(np.array(args.target), robot)
    sector = args.sector if args.sector is not None else select_sector(target)
    q = aim(target, sector, pan_reference=args.pan_reference)
    perp, _, ang = aim_errors(robot, q, target)
    result = {"target": target.tolist(), "sector": sector, "q_rad": q.round(9).tolist(),
              "q_deg": np.degrees(q).round(4).tolist(), "collision_free": robot.is_valid(q),
              "line_of_sight_clear": robot.line_of_sight_clear(q, target), "aim_error_m": perp, "aim_error_rad": ang}
    if args.json:
        print(json.dumps(result))
    else:
        print(f"sector {sector}: DOF1..DOF4 = {' '.join(f'{v:+.6f}' for v in q)} rad "
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
        return [(ti, spots[int(k * len(spots) / t.size)], k > 0 and int(k * len(spots) / t.size) != int((k - 1) * len(spots) / t.size))
                for k, ti in enumerate(t)]
    raise CliError(f"unknown script {name!r}")


def cmd_track(args: argparse.Namespace) -> int:
    """Run the Fig. 10 tracking strategy on a scripted target stream and report its events."""
    from ..library.tracker import Tracker, make_default_planner

    robot = _load_robot(args)
    if args.planner == "dimension-rrt":
        from ..library.path_library import dimension_rrt_planner

        plan = dimension_rrt_planner(robot, max_samples=args.samples, seed=args.seed)

        def planner(start: np.ndarray, goal: np.ndarray, i: int, j: int) -> np.ndarray:
            path = plan(start, goal, i, j) if i != j else None
            if path is None:
                raise RuntimeError(f"dimension-RRT found no path {i}->{j}")
            return path
    elif args.planner == "library":
        from ..library.path_library import PathLibrary, dimension_rrt_planner

        lib = PathLibrary.load(args.library, robot, plan=dimension_rrt_planner(robot, max_samples=args.samples))
        planner = lib.as_planner()
    else:
        planner = make_default_planner(robot, seed=args.seed)
    stream = _scripted_targets(args.script, args.duration, args.rate)
    result = Tracker(robot, planner).run(stream)
    kinds = ("aim", "cross-sector", "blind-area", "unreachable")
    summary = {k: result.count(k) for k in kinds}
    if args.output:
        header = "t,dof1,dof2,dof3,dof4,sector"
        np.savetxt(args.output, np.c_[result.times, result.configurations, result.sectors], delimiter=",",
                   header=header, comments="")
    if args.json:
        print(json.dumps({"script": args.script, "samples": len(stream), "trajectory_points": len(result.times),
                          "events": summary}))
    else:
        print(f"{args.script}: {len(stream)} target samples -> {len(result.times)} trajectory points; "
              + ", ".join(f"{k} {v}" for k, v in summary.items()))
        if args.output:
            print(f"wrote {args.output}")
    return 0


def _register_aim_track(sub: argparse._SubParsersAction, fmt: type) -> None:
    p = sub.add_parser("aim", help="aiming IK for a target", formatter_class=fmt,
                       description="Closed-form aiming IK (paper eqs. 1-11).\n\nexample:\n"
                                   "  tpee-ompl aim --target 5 2 1.5\n  tpee-ompl aim --target -4 -3 1 --sector 1 --json")
    p.add_argument("--target", type=_finite, nargs=3, required=True, metavar=("X", "Y", "Z"), help="metres, world frame")
    p.add_argument("--sector", type=_sector, default=None, help="posture sector (default: chosen from the target)")
    p.add_argument("--pan-reference", type=_finite, default=0.0, help="pan angle the smaller rotation is measured from")
    p.add_argument("--json", action="store_true")
    _add_model_args(p)
    p.set_defaults(func=cmd_aim)

    p = sub.add_parser("track", help="run the tracking strategy (Fig. 10) on a scripted target", formatter_class=fmt,
                       description="Track a scripted target: re-aim inside a pointing sector, plan cross-sector motions "
                                   "when it leaves.\n\nexample:\n  tpee-ompl track --script circle\n"
                                   "  tpee-ompl track --script jump --planner dimension-rrt -o traj.csv")
    p.add_argument("--script", choices=("circle", "jitter", "jump"), default="circle")
    p.add_argument("--planner", choices=("default", "dimension-rrt", "library"), default="default",
                   help="cross-sector planner: default (Table 3 straight motion, else RRTConnect), dimension-rrt, library")
    p.add_argument("--library", default=str(default_library_path()), help="path library file (with --planner library; default: the packaged one)")
    p.add_argument("--samples", type=_positive_int, default=2500, help="dimension-RRT sample cap")
    p.add_argument("--duration", type=_positive_float, default=20.0, help="seconds of target motion")
    p.add_argument("--rate", type=_positive_float, default=10.0, help="target samples per second")
    p.add_argument("--seed", type=int, default=1, help="OMPL / planner seed (>= 1)")
    p.add_argument("--json", action="store_true")
    p.add_argument("-o", "--output", help="write the trajectory as CSV")
    _add_model_args(p)
    p.set_defaults(func=cmd_track)


# ---------------------------------------------------------------------------------------- pictures
DEFAULT_SCENE_Q = (50.0, 20.0, 17.0, -37.0)  # degrees: sector 4 preset aiming forward-left-up
DEFAULT_SCENE_TARGET = (4.0, 1.5, 1.9)


def cmd_show(args: argparse.Namespace) -> int:
    """Draw the wearer, the arm at q and the line of sight to the target into a PNG."""
    from ..viz import scene as render

    robot = _load_robot(args)
    q = np.array(args.q) if args.q is not None else np.radians(DEFAULT_SCENE_Q)
    target = np.array(args.target) if args.target is not None else (np.array(DEFAULT_SCENE_TARGET) if args.q is None else None)
    out = render.save_scene(robot, robot.check_config(q), args.output, target=target, sectors=args.sectors)
    print(f"wrote {out} (q = {np.round(q, 4).tolist()} rad, valid: {robot.is_valid(q)})")
    return 0


def cmd_animate(args: argparse.Namespace) -> int:
    """Plan a cross-sector motion (or read one from --path JSON) and write an animation."""
    from ..viz import scene as render

    if args.path:
        try:
            with open(args.path) as fh:
                W = np.asarray(json.load(fh)["path"], dtype=float)
        except (OSError, KeyError, json.JSONDecodeError, TypeError) as exc:
            raise CliError(f"cannot read a path from {args.path}: {exc}") from None
        robot = _load_robot(args)
    else:
        result = _plan(args)
        robot = result.pop("_robot")
        if not result["exact"]:
            raise CliError(f"{args.planner} found no exact path ({result['status']}); nothing to animate")
        W = np.asarray(result["path"])
    (pa, ua), (pb, ub) = robot.muzzle(W[0]), robot.muzzle(W[-1])
    out = render.animate_path(robot, W, args.output, target_a=pa + 3 * ua, target_b=pb + 3 * ub, frames=args.frames)
    print(f"wrote {out} ({len(W)} waypoints, {args.frames} frames)")
    return 0


def cmd_workspace(args: argparse.Namespace) -> int:
    """Monte-Carlo pointing workspace (the paper's Fig. 4) into a PNG."""
    from ..viz import scene as render

    robot = _load_robot(args)
    render.pointing_workspace(robot, args.samples, np.random.default_rng(args.seed), args.output)
    print(f"wrote {args.output} ({args.samples} samples, seed {args.seed})")
    return 0


def cmd_view(args: argparse.Namespace) -> int:
    """Interactive 3-D view in meshcat (optional extra `viewer`)."""
    from ..viz import scene as render

    robot = _load_robot(args)
    q = np.array(args.q) if args.q is not None else np.radians(DEFAULT_SCENE_Q)
    render.view_meshcat(robot, robot.check_config(q), open_browser=not args.no_browser)
    print("meshcat viewer running; press Ctrl-C to stop")
    import time

    while True:
        time.sleep(1.0)


def _register_library(sub: argparse._SubParsersAction, fmt: type) -> None:
    from .library import register

    register(sub, fmt)


def _register_bench(sub: argparse._SubParsersAction, fmt: type) -> None:
    from ..bench.campaign import build_parser

    template = build_parser("tpee-ompl bench")
    p = sub.add_parser("bench", help="head-to-head benchmark campaign (OMPL Benchmark, SQLite, Table 4)",
                       formatter_class=fmt, description=(template.description or "") +
                       "\n\nexample:\n  tpee-ompl bench --max-queries 24 --samples 500 2500 --anytime 0.1 0.5 --workers 2",
                       parents=[template], add_help=False, conflict_handler="resolve")
    p.set_defaults(func=cmd_bench)


def cmd_bench(args: argparse.Namespace) -> int:
    """Run a benchmark campaign (delegates to :mod:`tpee_ompl.bench.campaign`)."""
    from ..bench import campaign as benchmark

    argv = args._argv
    return int(benchmark.main(argv[argv.index("bench") + 1 :]) or 0)


def _register_pictures(sub: argparse._SubParsersAction, fmt: type) -> None:
    p = sub.add_parser("show", help="draw a scene into a PNG", formatter_class=fmt,
                       description="Draw the wearer, the arm and the line of sight.\n\nexample:\n"
                                   "  tpee-ompl show -o scene.png\n  tpee-ompl show --q 0.87 0.35 0.3 -0.6 --target 4 1.5 1.9 --sectors -o s.png")
    p.add_argument("--q", type=_finite, nargs=4, metavar="Q", help="DOF1..DOF4 in radians (default: a sector-4 scene)")
    p.add_argument("--target", type=_finite, nargs=3, metavar=("X", "Y", "Z"), help="target point (m, world frame)")
    p.add_argument("--sectors", action="store_true", help="overlay the posture sectors")
    p.add_argument("-o", "--output", default="scene.png")
    _add_model_args(p)
    p.set_defaults(func=cmd_show)

    p = sub.add_parser("animate", help="animate a cross-sector motion (GIF/MP4)", formatter_class=fmt,
                       description="Plan a cross-sector motion and animate it, muzzle trace drawn.\n\nexample:\n"
                                   "  tpee-ompl animate --from 1 --to 4 --planner dimension-rrt -o motion.gif\n"
                                   "  tpee-ompl plan --from 2 --to 3 --json > p.json && tpee-ompl animate --path p.json -o m.gif")
    _add_plan_args(p)
    p.add_argument("--path", help="JSON file with a 'path' list of waypoints (e.g. from plan --json)")
    p.add_argument("--frames", type=_positive_int, default=40)
    p.add_argument("-o", "--output", default="motion.gif")
    p.set_defaults(func=cmd_animate)

    p = sub.add_parser("workspace", help="Monte-Carlo pointing workspace (Fig. 4)", formatter_class=fmt,
                       description="Sample collision-free configurations and draw where the barrel can point.\n\n"
                                   "example:\n  tpee-ompl workspace --samples 4000 -o workspace.png")
    p.add_argument("--samples", type=_positive_int, default=4000)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("-o", "--output", default="workspace.png")
    _add_model_args(p)
    p.set_defaults(func=cmd_workspace)

    p = sub.add_parser("view", help="interactive meshcat view (pip install 'tpee_ompl[viewer]')", formatter_class=fmt,
                       description="Open the model in Pinocchio's MeshcatVisualizer.\n\nexample:\n  tpee-ompl view --q 0.87 0.35 0 0")
    p.add_argument("--q", type=_finite, nargs=4, metavar="Q")
    p.add_argument("--no-browser", action="store_true")
    _add_model_args(p)
    p.set_defaults(func=cmd_view)


# ---------------------------------------------------------------------------------------- parser
def _add_model_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--urdf", default=None, help="URDF file (default: the packaged wearer + arm)")
    p.add_argument("--srdf", default=None, help="SRDF file with disabled collision pairs (with --urdf)")


def _add_plan_args(p: argparse.ArgumentParser, required: bool = False) -> None:
    p.add_argument("--from", dest="from_sector", type=_sector, required=required, default=1, help="start posture sector (1-4)")
    p.add_argument("--to", dest="to_sector", type=_sector, required=required, default=4, help="goal posture sector (1-4)")
    p.add_argument("--planner", choices=PLANNERS, default="dimension-rrt")
    p.add_argument("--time", type=_positive_float, default=5.0, help="time limit in seconds (default 5)")
    p.add_argument("--samples", type=_positive_int, default=None, help="sample / iteration cap")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--queries", default="planning_necessary", help="query set name or JSON file")
    p.add_argument("--query-index", type=int, default=0, help="which query of that pair (default 0)")
    p.add_argument("--start", type=_finite, nargs=4, default=None, metavar="Q", help="start DOF1..DOF4 (rad)")
    p.add_argument("--goal", type=_finite, nargs=4, default=None, metavar="Q", help="goal DOF1..DOF4 (rad)")
    _add_model_args(p)


def get_argument_parser() -> argparse.ArgumentParser:
    """The full ``tpee-ompl`` argument parser."""
    parser = argparse.ArgumentParser(prog="tpee-ompl", description=__doc__.split("\n")[0])
    parser.add_argument("-v", "--verbose", action="store_true", help="log at INFO level")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    fmt = argparse.RawDescriptionHelpFormatter

    p = sub.add_parser("plan", help="plan one cross-sector motion", formatter_class=fmt,
                       description="Plan a cross-sector motion between the first stored query of a sector pair "
                                   "(or --start/--goal).\n\nexample:\n  tpee-ompl plan --from 1 --to 4 --planner dimension-rrt"
                                   "\n  tpee-ompl plan --from 2 --to 3 --planner rrtstar --samples 1000 --json")
    _add_plan_args(p, required=True)
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p.set_defaults(func=cmd_plan)

    for register in _EXTRA_COMMANDS:
        register(sub, fmt)
    return parser


_EXTRA_COMMANDS: list[Callable[[argparse._SubParsersAction, type], None]] = [_register_aim_track, _register_pictures, _register_bench, _register_library]


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``tpee-ompl``; returns the exit code."""
    parser = get_argument_parser()
    args = parser.parse_args(argv)
    args._argv = list(sys.argv[1:] if argv is None else argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    try:
        return int(args.func(args) or 0)
    except (CliError, ValueError, FileNotFoundError, ImportError, KeyError, RuntimeError) as exc:
        msg = exc.args[0] if isinstance(exc, KeyError) and exc.args else exc
        print(f"tpee-ompl {args.command}: error: {msg}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"tpee-ompl {args.command}: interrupted", file=sys.stderr)
        return 130
    finally:
        gc.collect()  # break si <-> Python checker cycles before exit (nanobind leak warnings otherwise)


if __name__ == "__main__":
    sys.exit(main())
