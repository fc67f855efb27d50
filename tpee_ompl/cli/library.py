"""``tpee-ompl library build|query|stats``: the cross-sector path library on the command line.

:func:`register` adds the ``library`` subcommand to the main parser; each sub-subcommand sets
``func`` (``args -> int``).  Usage errors (a bad option, a missing input file, an existing output
without ``--force``) are raised as :class:`~tpee_ompl.cli._common.CliError` before any work; a damaged
library or query file found while working is a LibraryFileError / QuerySetError (exit code 1).
"""

from __future__ import annotations

import argparse
import json
import logging
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..library.build import LibraryBuildOptions
from ..library.demos import dimension_rrt_planner
from ..library.dmp import DMPOptions
from ..library.storage import library_model_hash, library_settings
from ..library import PathLibrary
from ..planning.paths import path_length
from ..resources import default_library_path
from ._common import (
    CliError,
    Parser,
    add_force_arg,
    add_model_args,
    argument,
    check_input_file,
    check_library_model,
    check_output,
    finite,
    index,
    load_robot,
    nonempty,
    numpy_seed,
    on_postures,
    positive_int,
    sector,
)

if TYPE_CHECKING:
    from ..model.wearer_arm import WearerArm

__all__ = ["DEFAULT_LIBRARY", "build_parser", "register", "run_build", "run_query", "run_stats"]

log = logging.getLogger(__name__)

DEFAULT_LIBRARY = default_library_path()
"""Default library file, shipped inside the package (``make library`` rebuilds it)."""
_BUILD_DEFAULTS = LibraryBuildOptions()
"""The ``library build`` defaults: those of :class:`~tpee_ompl.library.build.LibraryBuildOptions`."""

_BUILD_EXAMPLE = """example:
  tpee-ompl library build --workers 2 --library /tmp/default.npz      # the packaged library's settings
  tpee-ompl library build --pairs 1-2 3-4 --per-pair 3 --max-samples 500 --library /tmp/small.npz
"""
_QUERY_EXAMPLE = """example:
  tpee-ompl library query --query-set planning_necessary --index 0
  tpee-ompl library query --from 1 --to 3 --start -0.8727 2.7925 3.0947 -0.2065 --goal -0.8727 0.3491 0.4239 -0.6484 --json
"""
_STATS_EXAMPLE = """example:
  tpee-ompl library stats                       # the packaged default library
"""


def _pair(text: str) -> tuple[int, int]:
    try:
        i, j = (int(v) for v in text.replace(",", "-").split("-"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"a sector pair is written I-J (e.g. 1-3), got {text!r}") from None
    if not (1 <= i <= 4 and 1 <= j <= 4 and i != j):
        raise argparse.ArgumentTypeError(f"sectors must be two different numbers in 1..4, got {text!r}")
    return i, j


def _check_library_file(path: Path) -> Path:
    """``--library`` names an existing file (a usage error otherwise, with the fix)."""
    return check_input_file(path, "--library", "path library",
                            hint=": build one with 'tpee-ompl library build --library FILE' ('make library' in a source checkout)")


def _load(path: Path, robot: WearerArm, fallback: bool = True,
          max_samples: int = _BUILD_DEFAULTS.max_samples) -> PathLibrary:
    _check_library_file(path)
    check_library_model(path, robot)
    plan = dimension_rrt_planner(robot, max_samples=max_samples) if fallback else None
    return PathLibrary.load(path, robot, plan=plan)


def _build_options(args: argparse.Namespace) -> LibraryBuildOptions:
    """The build settings of ``library build``'s arguments; a bad one raises ValueError naming its option."""
    given = {"per_pair": args.per_pair, "seed": args.seed, "min_difference": args.min_difference,
             "max_attempts": args.max_attempts, "max_samples": args.max_samples, "timeout": args.timeout,
             "demo_margins": tuple(args.demo_margins), "workers": args.workers,
             "dmp_options": DMPOptions(scaling=args.dmp_scaling), "progress": not args.no_progress}
    if args.pairs:
        given["pairs"] = tuple(args.pairs)
    try:
        return LibraryBuildOptions(**given)
    except ValueError as exc:
        message = str(exc)
        name = next((n for n in given if message.startswith((n, n.replace("_", " ")))), None)
        if name is None:
            raise CliError(message) from None
        raise CliError(f"--{name.replace('_', '-')}: {message}") from None


def run_build(args: argparse.Namespace) -> int:
    """Build a library with the default sampler and dimension-RRT and save it."""
    options = _build_options(args)
    out = check_output(args.library, "--library", args.force, (".npz",))
    robot = load_robot(args)
    t0 = time.perf_counter()
    lib = PathLibrary.build_default(robot, options)
    lib.save(out, force=args.force)
    s = lib.stats()
    print(f"wrote {out}: {len(lib)} demonstrations in {len(lib.pairs)} pairs "
          f"({s['build_sampled']} drawn, {s['build_rejected_similar']} too similar, "
          f"{s['build_plan_failed']} not planned) in {time.perf_counter() - t0:.1f} s, "
          f"{out.stat().st_size / 1e6:.2f} MB")
    return 0


def run_query(args: argparse.Namespace) -> int:
    """Answer one query from the library and print the outcome (and the path with --json)."""
    _check_library_file(Path(args.library))
    robot = load_robot(args)
    given = [n for n, v in (("--from", args.from_sector), ("--to", args.to_sector), ("--start", args.start),
                            ("--goal", args.goal)) if v is not None]
    if args.query_set is not None:
        from ..model.queries import load_queries

        if given:
            raise CliError(f"give --query-set NAME --index K, or --from --to --start --goal, not both ({' '.join(given)})")
        try:
            queries = load_queries(args.query_set, robot)
        except OSError as exc:  # missing, a folder, a pipe, not readable
            raise CliError(f"--query-set: {exc}") from None
        k = 0 if args.index is None else args.index
        if k >= len(queries):
            raise CliError(f"--index must be in 0..{len(queries) - 1} for query set {args.query_set!r}, got {k}")
        q = queries[k]
        start, goal, i, j = q.start, q.goal, q.from_sector, q.to_sector
    else:
        if args.index is not None:
            raise CliError("--index picks a query of --query-set: give --query-set NAME too")
        missing = [n for n in ("--from", "--to", "--start", "--goal") if n not in given]
        if missing:
            raise CliError(f"give --query-set NAME --index K, or all of --from --to --start --goal (missing {' '.join(missing)})")
        if args.from_sector == args.to_sector:
            raise CliError(f"--from and --to are both sector {args.from_sector}: a query joins two sectors")
        i, j = args.from_sector, args.to_sector
        start, goal, off_posture = on_postures(args.start, args.goal, i, j)
        with argument("--start/--goal"):
            robot.check_free(start, "start")
            robot.check_free(goal, "goal")
        if off_posture:
            raise CliError(off_posture)
    lib = _load(Path(args.library), robot, fallback=not args.no_fallback)
    res = lib.query(start, goal, i, j)
    if args.json:
        print(json.dumps({"from": i, "to": j, "outcome": res.outcome, "demo_index": res.demo_index,
                          "candidates_tried": res.candidates_tried, "seconds": res.seconds,
                          "path": None if res.path is None else np.round(res.path, 6).tolist()}))
    else:
        extra = "" if res.path is None else f", {len(res.path)} waypoints, length {path_length(res.path):.3f} rad"
        print(f"{i}->{j}: {res.outcome} (demo {res.demo_index}, {res.candidates_tried} DMP candidates) "
              f"in {res.seconds * 1e3:.1f} ms{extra}")
    return 0 if res.path is not None else 1


def run_stats(args: argparse.Namespace) -> int:
    """Print what a library file holds: demonstrations per pair, build parameters and counters."""
    path = _check_library_file(Path(args.library))
    robot = load_robot(args)
    if library_model_hash(path) != robot.model_hash:  # described from its metadata: the demos need their model
        meta = library_settings(path)
        print(f"{path}: built for model {meta['model_hash']}, not the loaded model {robot.model_hash} (its "
              "demonstrations are read with the --urdf/--srdf it was built for)")
        print("pairs: " + ", ".join(f"{i}->{j}" for i, j in meta["pairs"]))
        print(f"per_step {meta['per_step']}, query_stride {meta['query_stride']}, n_candidates {meta['n_candidates']}")
        print("build parameters: " + json.dumps(meta["build_params"]))
        print("build counters: " + json.dumps(meta["build_stats"] or {}))
        return 0
    lib = _load(path, robot, fallback=False)
    print(f"{path}: {len(lib)} demonstrations, {path.stat().st_size / 1e6:.2f} MB, model {lib.robot.model_hash}")
    print("per pair: " + ", ".join(f"{i}->{j}: {len(pd.starts)}" for (i, j), pd in sorted(lib.pairs.items())))
    print(f"per_step {lib.per_step}, query_stride {lib.query_stride}, n_candidates {lib.n_candidates}")
    print("build parameters: " + json.dumps(lib.build_params))
    s = lib.stats()
    print("build counters: " + json.dumps({k: v for k, v in s.items() if k.startswith("build_")}))
    return 0


def register(subparsers: argparse._SubParsersAction, formatter_class: type = argparse.RawDescriptionHelpFormatter) -> argparse.ArgumentParser:
    """Add ``library build|query|stats`` to the main CLI's subparsers; returns the ``library`` parser."""
    lib = subparsers.add_parser("library", help="build, query or inspect the DMP path library",
                                description="The cross-sector DMP path library (paper sec. 4.2).",
                                epilog="examples:\n" + "".join(e.split("\n", 1)[1] for e in (_BUILD_EXAMPLE, _QUERY_EXAMPLE, _STATS_EXAMPLE)), formatter_class=formatter_class)
    sub = lib.add_subparsers(dest="library_command", metavar="{build,query,stats}", required=True)

    def common(p: argparse.ArgumentParser) -> None:
        p.add_argument("--library", type=nonempty, default=DEFAULT_LIBRARY, metavar="FILE",
                       help=f"library file (.npz), default {DEFAULT_LIBRARY}")
        add_model_args(p)  # a library is made for one model: its file records the model's hash

    b = sub.add_parser("build", help="build a library (dimension-RRT demonstrations)", epilog=_BUILD_EXAMPLE,
                       description="Build a path library: per ordered sector pair, dimension-RRT demonstrations "
                       "learned as DMPs (paper sec. 4.2).", formatter_class=formatter_class)
    # no default: the packaged library lives inside the installed package, which a build must not write into
    # unasked (``make library`` names it on purpose); queries and stats read it by default
    b.add_argument("--library", type=nonempty, required=True, metavar="FILE",
                   help=f"the library file (.npz) to write (the packaged one, read by default elsewhere: {DEFAULT_LIBRARY})")
    add_model_args(b)
    d = _BUILD_DEFAULTS
    b.add_argument("--per-pair", type=positive_int, default=d.per_pair,
                   help=f"demonstrations per ordered sector pair (default {d.per_pair})")
    b.add_argument("--seed", type=numpy_seed, default=d.seed,
                   help=f"seed of the sampler and the planner, 0..2^32-1 (default {d.seed})")
    b.add_argument("--pairs", type=_pair, nargs="+", metavar="I-J",
                   help=f"sector pairs (default all {len(d.pairs)})")
    b.add_argument("--min-difference", type=finite, default=d.min_difference,
                   help="new demo kept only if its DOF3/DOF4 (start, goal) differs by this many rad "
                        f"(default {d.min_difference:g})")
    b.add_argument("--max-attempts", type=positive_int, default=d.max_attempts,
                   help="draws per pair before giving up on per-pair (default 3 x per-pair)")
    b.add_argument("--max-samples", type=positive_int, default=d.max_samples,
                   help=f"dimension-RRT samples per demo (default {d.max_samples})")
    b.add_argument("--timeout", type=finite, default=d.timeout,
                   help=f"dimension-RRT time limit per demo, s (default {d.timeout:g})")
    b.add_argument("--demo-margins", type=float, nargs="*", default=list(d.demo_margins), metavar="M",
                   help="margins (m) around the pointing system tried, widest first, before the robot's own "
                        f"when planning a demo (default {' '.join(map(str, d.demo_margins))}; none: robot's margin only)")
    b.add_argument("--workers", type=positive_int, default=d.workers,
                   help=f"processes building the pairs in parallel (default {d.workers})")
    b.add_argument("--dmp-scaling", choices=("none", "amplitude"), default=d.dmp_options.scaling,
                   help="DMP forcing: 'amplitude' = eq. 13's x(g - y0), 'none' = absolute "
                        f"(default {d.dmp_options.scaling}: eq. 13's scaling shrinks a demo's detour around the "
                        "backpack, or mirrors it into the body, for a query whose pan moves less far or the other "
                        "way; absolute forcing shifts the detour unchanged)")
    b.add_argument("--no-progress", action="store_true", help="no progress bar (pairs done, time left)")
    add_force_arg(b)
    b.set_defaults(func=run_build)

    q = sub.add_parser("query", help="answer one query", epilog=_QUERY_EXAMPLE, formatter_class=formatter_class,
                       description="Answer one cross-sector query from the library: its path, validated, and how it "
                       "was found (dmp, repaired, fallback).")
    common(q)
    q.add_argument("--query-set", metavar="NAME", type=nonempty, help="take the query from a named set (e.g. planning_necessary)")
    q.add_argument("--index", type=index, default=None, help="index in --query-set, from 0 (default 0)")
    q.add_argument("--from", dest="from_sector", type=sector, help="start sector (1-4)")
    q.add_argument("--to", dest="to_sector", type=sector, help="goal sector (1-4)")
    q.add_argument("--start", type=finite, nargs=4, metavar="Q", help="start configuration, 4 angles in rad")
    q.add_argument("--goal", type=finite, nargs=4, metavar="Q", help="goal configuration, 4 angles in rad")
    q.add_argument("--no-fallback", action="store_true", help="do not fall back to dimension-RRT")
    q.add_argument("--json", action="store_true", help="print the result (with the path) as JSON")
    q.set_defaults(func=run_query)

    s = sub.add_parser("stats", help="describe a library file", epilog=_STATS_EXAMPLE, formatter_class=formatter_class,
                       description="Describe a library file: its model, settings and demonstrations per sector pair.")
    common(s)
    s.set_defaults(func=run_stats)
    return lib


def build_parser() -> argparse.ArgumentParser:
    """A stand-alone parser with only the ``library`` subcommand (for scripts and tests)."""
    parser = Parser(prog="tpee-ompl", formatter_class=argparse.RawDescriptionHelpFormatter)
    register(parser.add_subparsers(dest="command", required=True), argparse.RawDescriptionHelpFormatter)
    return parser
