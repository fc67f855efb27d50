"""``tpee-ompl bench`` and ``experiments/run_benchmark.py``: a benchmark campaign from the command line.

:func:`register` adds the ``bench`` subcommand to the main parser (``func`` = :func:`run`);
:func:`main` is the stand-alone entry point.  Every campaign option's default is the matching
:class:`~tpee_ompl.bench.config.CampaignConfig` field's default (one source).  Building the parser
imports no OMPL (only :mod:`tpee_ompl.bench.config`); running a campaign does.
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import os
import re
import sys
import traceback
from collections.abc import Sequence
from pathlib import Path

from ..bench.config import CHECKERS, DEFAULT_CHECKERS, KNOWN_PLANNERS, CampaignConfig, check_planner_name
from ..bench.problems import DEFAULT_PROBLEM, get_problem
from ..signals import interrupts
from ._common import Parser, count, nonempty, positive_int, seconds, seed

__all__ = ["DESCRIPTION", "EXAMPLE", "add_arguments", "build_parser", "config_from_args", "list_problems",
           "main", "register", "run"]

DESCRIPTION = "Benchmark dimension-RRT against OMPL planners (ompl.tools.Benchmark)."
EXAMPLE = ("example:\n  tpee-ompl bench --max-queries 24 --samples 500 2500 --anytime 0.1 0.5 --workers 2\n"
           "  tpee-ompl bench --list-problems\n  tpee-ompl bench --problem arm6 --samples 500 --anytime 0.1 0.5 1")


def _default(name: str):
    """The default of a :class:`CampaignConfig` field (tuples as lists, as argparse gives them)."""
    f = next(f for f in dataclasses.fields(CampaignConfig) if f.name == name)
    v = f.default_factory() if f.default is dataclasses.MISSING else f.default
    return list(v) if isinstance(v, tuple) else v


def _planner(text: str) -> str:
    """argparse type: a planner name (:func:`~tpee_ompl.bench.config.check_planner_name`)."""
    try:
        return check_planner_name(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _problem(text: str) -> str:
    """argparse type: a problem name (:data:`~tpee_ompl.bench.problems.PROBLEM_NAMES`)."""
    try:
        return get_problem(text).name
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


_OPTION_OF = {"sample_caps": "--samples", "anytime_budgets": "--anytime", "iteration_planners": "--planners",
              "anytime_planners": "--anytime-planners", "alt_checker_queries": "--alt-checker-queries",
              "alt_checker_caps": "--alt-checker-samples", "anytime_queries": "--anytime-queries",
              "max_queries": "--max-queries", "max_time": "--max-time", "queries": "--queries", "name": "--name",
              "problem": "--problem", "checkers": "--checkers",
              "runs": "--runs", "workers": "--workers", "seed": "--seed", "out": "--out", "resume": "--resume",
              "scheduler": "--dask"}
""":class:`CampaignConfig` field -> option, to name the option in a refusal."""


def _user_message(exc: BaseException, given: dict[str, str] | None = None) -> str:
    """``exc`` as one line, naming the command-line option instead of the configuration field (``given``: fields
    that another option set, e.g. the scheduler by ``--scheduler``)."""
    msg = " ".join(str(exc).split())
    for field_name, option in {**_OPTION_OF, **(given or {})}.items():
        if msg.startswith(field_name + " ") or msg.startswith(field_name + ":"):
            msg = option + msg[len(field_name):]
        elif "_" in field_name:
            msg = re.sub(rf"\b{field_name}\b", option, msg)
    return msg


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Add the campaign, executor and resume options to ``p``."""
    p.add_argument("--problem", type=_problem, default=_default("problem"),
                   help="benchmark problem (default: %(default)s; --list-problems lists them)")
    p.add_argument("--list-problems", action="store_true", help="list the problems (name, dimension, queries) and exit")
    p.add_argument("--queries", type=nonempty, default=_default("queries"),
                   help="query-set name or JSON file, for problems that read query sets (default: the problem's "
                        "own, for the wearer planning_necessary)")
    p.add_argument("--name", type=nonempty, default=None, help="results folder suffix (default: the query-set name)")
    p.add_argument("--samples", type=positive_int, nargs="*", default=_default("sample_caps"),
                   help="sample/iteration caps of the Table-4 comparison (default: %(default)s); none to skip")
    p.add_argument("--anytime", type=seconds, nargs="*", default=_default("anytime_budgets"),
                   help="time budgets (s) of the anytime comparison (default: %(default)s); none to skip")
    p.add_argument("--planners", type=_planner, nargs="+", default=_default("iteration_planners"),
                   help="iteration-matched planners; the first is compared with the second (default: %(default)s); "
                        f"built in: {' '.join(KNOWN_PLANNERS)}, or module:function naming a factory")
    p.add_argument("--anytime-planners", type=_planner, nargs="+", default=None,
                   help=f"(default: the problem's planners; the wearer's: {' '.join(_default('anytime_planners'))})")
    p.add_argument("--checkers", nargs="+", default=None, choices=CHECKERS,
                   help="motion validators; the first is the headline (default: the problem's: for the wearer "
                        f"{' '.join(_default('checkers'))}, for the generic problems discrete only)")
    p.add_argument("--alt-checker-queries", type=count, default=_default("alt_checker_queries"),
                   help="run the non-headline validators on the first k queries only (default: all)")
    p.add_argument("--alt-checker-samples", type=positive_int, nargs="+", default=_default("alt_checker_caps"),
                   help="caps for the non-headline validators (default: all --samples)")
    p.add_argument("--anytime-queries", type=count, default=_default("anytime_queries"),
                   help="anytime comparison on the first k queries only")
    p.add_argument("--max-queries", type=positive_int, default=_default("max_queries"),
                   help="use N queries (the wearer's: round-robin over the ordered sector pairs; a problem's own: "
                        "at most as many as it has)")
    p.add_argument("--runs", type=positive_int, default=_default("runs"), help="runs per planner per experiment (default: %(default)s)")
    p.add_argument("--workers", type=positive_int, default=None,
                   help=f"worker processes, one fresh process per query (default: {_default('workers')}; with "
                        "--resume: the campaign's own, unless given)")
    p.add_argument("--seed", type=seed, default=_default("seed"),
                   help="campaign seed in [1, 2**32-1]; query k's process uses seed + k (default: %(default)s)")
    p.add_argument("--max-time", type=seconds, default=_default("max_time"), help="safety limit per iteration-capped run, s")
    p.add_argument("--out", type=nonempty, default=_default("out"),
                   help="parent folder of the timestamped results folder (default: %(default)s, under the current folder)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    g = p.add_argument_group("executor (default: local process pool of --workers)")
    g.add_argument("--dask", metavar="local|tcp://HOST:PORT", type=nonempty, default=None,
                   help="run the queries as Dask tasks: 'local' starts a LocalCluster here, an address uses that "
                        "scheduler (needs the dask extra: pip install 'tpee_ompl[dask]')")
    g.add_argument("--scheduler", metavar="tcp://HOST:PORT", type=nonempty, default=None, help="same as --dask tcp://HOST:PORT")
    g.add_argument("--dask-workers", type=positive_int, default=None, help="workers of --dask local (default: 2)")
    g.add_argument("--retries", type=count, default=None, help="Dask retries of a task that raises (default: 2)")
    p.set_defaults(bench_prog=p.prog)
    p.add_argument("--resume", metavar="DIR", type=nonempty, default=None,
                   help="finish an interrupted campaign in DIR: run only its missing experiments (configuration "
                        "from DIR/campaign.json, so the other campaign options are refused; --workers and the "
                        "executor options apply)")


def build_parser(prog: str | None = None) -> argparse.ArgumentParser:
    """The stand-alone parser (``experiments/run_benchmark.py``)."""
    p = Parser(prog=prog, description=DESCRIPTION)
    add_arguments(p)
    return p


def register(subparsers: argparse._SubParsersAction,
             formatter_class: type = argparse.RawDescriptionHelpFormatter) -> argparse.ArgumentParser:
    """Add the ``bench`` subcommand (``func`` = :func:`run`) to the main ``tpee-ompl`` parser; return it."""
    p = subparsers.add_parser("bench", help="head-to-head benchmark campaign (OMPL Benchmark, SQLite, Table 4)",
                              formatter_class=formatter_class, description=f"{DESCRIPTION}\n\n{EXAMPLE}")
    add_arguments(p)
    p.set_defaults(func=run)
    return p


def config_from_args(args: argparse.Namespace) -> CampaignConfig:
    """A :class:`CampaignConfig` from parsed arguments; checkers and anytime planners default to the problem's."""
    problem = get_problem(getattr(args, "problem", DEFAULT_PROBLEM))
    name = args.name or (Path(args.queries).stem if args.queries else problem.default_queries or problem.name)
    extra = {}
    if args.checkers is not None:
        extra["checkers"] = tuple(args.checkers)
    if args.anytime_planners is not None:
        extra["anytime_planners"] = tuple(args.anytime_planners)
    return CampaignConfig.for_problem(
        problem.name,
        name=name,
        queries=args.queries,
        sample_caps=tuple(args.samples or ()),
        iteration_planners=tuple(args.planners),
        alt_checker_queries=args.alt_checker_queries,
        alt_checker_caps=tuple(args.alt_checker_samples) if args.alt_checker_samples else None,
        anytime_budgets=tuple(args.anytime or ()),
        anytime_queries=args.anytime_queries,
        max_queries=args.max_queries,
        runs=args.runs,
        workers=_default("workers") if args.workers is None else args.workers,
        seed=args.seed,
        out=args.out,
        max_time=args.max_time,
        **extra,
    )


def list_problems() -> int:
    """Print the problems: name, dimension, queries and a one-line description; returns 0."""
    from ..bench.problems import problem_table

    rows = problem_table()
    width = max(len(r["name"]) for r in rows)
    print(f"{'problem':{width}s}  dim  queries  description")
    for r in rows:
        n = str(r["queries"]) if r["queries"] is not None else "n/a"
        note = f" [unavailable: {r['note']}]" if r["note"] else ""
        default = " (default)" if r["name"] == DEFAULT_PROBLEM else ""
        print(f"{r['name']:{width}s}  {r['dimension']:>3d}  {n:>7s}  {r['description']}{default}{note}")
    return 0


def run(args: argparse.Namespace) -> int:
    """Run (or ``--resume``) a campaign from parsed arguments; print the ratio table and where the files are.

    Everything is checked before anything is created.  Returns the exit code: 0; 2 for bad input
    (one line on stderr naming the option or file); 1 when the campaign failed at run time or
    finished with lost queries (listed; ``--resume`` runs them); 130 when interrupted.
    """
    from ..bench.campaign import load_campaign, prepare_campaign, resume_campaign, run_campaign
    from ..bench.executors import make_executor
    from ..model.queries import QuerySetError

    if getattr(args, "list_problems", False):
        return list_problems()
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    prog = getattr(args, "bench_prog", "bench")
    try:
        dask = args.scheduler or args.dask
        for option, value in (("--dask-workers", args.dask_workers), ("--retries", args.retries)):
            if value is not None and not dask:
                raise ValueError(f"{option} applies to a Dask executor: give --dask too")
        if args.dask_workers is not None and dask != "local":
            raise ValueError("--dask-workers sizes --dask local; a scheduler at an address has its own workers")
        _refuse_options_that_change_nothing(args)
        if args.resume:  # its own worker count (the checker's threads follow it) unless --workers is given
            if Path(args.resume).is_dir() and not os.access(args.resume, os.W_OK | os.X_OK):
                raise ValueError(f"--resume {args.resume}: the folder is not writable (the campaign's logs, lock and "
                                 "database are written there)")
            saved = load_campaign(args.resume)["config"].get("workers", _default("workers"))
            workers = saved if args.workers is None else args.workers
            config = plan = None
        else:
            config = config_from_args(args)
            workers = config.workers
            plan = prepare_campaign(config)
        cores = os.cpu_count() or 1
        if not (args.scheduler or args.dask) and workers > cores:  # timed runs then share cores: their figures suffer
            logging.getLogger(__name__).warning("--workers %d on a machine with %d core(s): runs compete for the CPU, "
                                                "so times and time-budgeted results are not those of one run alone",
                                                workers, cores)
        executor = make_executor(workers, dask=args.scheduler or args.dask,
                                 dask_workers=2 if args.dask_workers is None else args.dask_workers,
                                 retries=2 if args.retries is None else args.retries)
    except (ValueError, FileNotFoundError, ImportError) as exc:
        given = {"scheduler": "--scheduler"} if args.scheduler and not args.dask else None
        print(f"{prog}: error: {_user_message(exc, given)}", file=sys.stderr)
        # a damaged query file and a missing optional extra (dask) are runtime conditions, as in ``plan`` and ``view``
        return 1 if isinstance(exc, (QuerySetError, ImportError)) else 2
    seen = interrupts()
    try:
        if args.resume:
            result = resume_campaign(args.resume, executor=executor, workers=workers,
                                     progress_bar=not args.no_progress)
        else:
            result = run_campaign(config, executor=executor, progress_bar=not args.no_progress, plan=plan)
    except KeyboardInterrupt as exc:  # a second Ctrl-C while the database was built
        return _interrupted(prog, getattr(exc, "directory", None) or args.resume)
    except Exception as exc:  # noqa: BLE001 (a runtime failure: one line, no traceback unless -v)
        if interrupts() > seen:  # the interrupt came back as another error (an ImportError of an import it stopped)
            return _interrupted(prog, args.resume)
        if getattr(args, "verbose", False):
            traceback.print_exc()
        kind = "" if isinstance(exc, (ValueError, OSError, RuntimeError)) else f"{type(exc).__name__}: "  # as cli.main
        print(f"{prog}: error: {kind}{_user_message(exc)}", file=sys.stderr)
        return 1
    _print_result(result)
    if result.interrupted:
        print("campaign was interrupted: the database holds the finished experiments only; "
              f"finish it with --resume {result.directory}")
        return 130
    if result.failed_tasks or result.skipped_logs:
        lost = _lost_line(result.failed_tasks)
        bad = ", ".join(p.name for p in result.skipped_logs)
        print(f"{prog}: error: campaign finished incomplete: {len(result.failed_tasks)} query(ies) lost"
              + (f": {lost}" if lost else "") + (f"; unreadable logs: {bad}" if bad else "")
              + f"; run them again with --resume {result.directory}", file=sys.stderr)
        return 1
    return 0


_CAMPAIGN_OPTIONS = ("problem", "queries", "name", "samples", "anytime", "planners", "anytime_planners", "checkers",
                     "alt_checker_queries", "alt_checker_samples", "anytime_queries", "max_queries", "runs", "seed",
                     "max_time", "out")
"""Options that make the configuration: a resumed campaign takes them from its ``campaign.json``."""


def _refuse_options_that_change_nothing(args: argparse.Namespace) -> None:
    """Raise ValueError naming an option that would be ignored: a campaign option with ``--resume``, the
    anytime or non-headline-validator subsets of a comparison that does not run."""
    if args.resume:
        defaults = vars(build_parser().parse_args([]))
        plain = lambda v: tuple(v) if isinstance(v, list) else v  # noqa: E731 (a list given, a tuple by default)
        given = ["--" + d.replace("_", "-") for d in _CAMPAIGN_OPTIONS if plain(getattr(args, d)) != plain(defaults[d])]
        if given:
            raise ValueError(f"--resume takes the campaign's configuration from its campaign.json: {', '.join(given)} "
                             "would be ignored (drop it, or start a new campaign)")
        return
    if args.anytime_queries is not None and not args.anytime:
        raise ValueError("--anytime-queries applies to the anytime comparison: give --anytime budgets too")
    checkers = (args.checkers if args.checkers is not None
                else [c for c in get_problem(args.problem).checkers if c in DEFAULT_CHECKERS])  # as for_problem
    for option, value in (("--alt-checker-queries", args.alt_checker_queries),
                          ("--alt-checker-samples", args.alt_checker_samples)):
        if value is None:
            continue
        if not args.samples:
            raise ValueError(f"{option} applies to the sample-cap comparison: give --samples too")
        if len(checkers) < 2:
            raise ValueError(f"{option} applies to the motion validators after the first: this campaign has one "
                             f"({checkers[0]}); name more with --checkers")


def _lost_line(failed: list[dict], shown: int = 5) -> str:
    """The lost queries in one line, one entry per reason (a planner factory that fails fails every query: its
    error was repeated once per query, 18 kB for 120)."""
    by_reason: dict[str, list[dict]] = {}
    for f in failed:
        by_reason.setdefault(" ".join(str(f["reason"]).split()), []).append(f)
    parts = []
    for reason, fs in by_reason.items():
        ids = [str(f["query_id"]) for f in fs]
        which = (f"query {ids[0]}" if len(ids) == 1 else f"queries {', '.join(ids[:shown])}"
                 + (f" and {len(ids) - shown} more" if len(ids) > shown else ""))
        parts.append(f"{which} ({reason}, {sum(len(f['missing_logs']) for f in fs)} experiment(s))")
    return "; ".join(parts)


def _interrupted(prog: str, where: object) -> int:
    """Say that the campaign was interrupted and how to finish it (``where``: its folder, None when none was made);
    the exit code 130."""
    if where is None:  # (it said "--resume DIR" of a folder that did not exist)
        print(f"{prog}: interrupted before the campaign started; nothing was written", file=sys.stderr)
    else:
        print(f"{prog}: interrupted; finished logs are kept: finish the campaign with --resume {where}",
              file=sys.stderr)
    return 130


def _print_result(result) -> None:
    """Where the campaign's files are, the report's headline tables and how many runs succeeded."""
    if result.report.get("headline"):
        print(result.report["headline"])
    if "runs" in result.report:
        print(f"runs: {result.report['successes']} of {result.report['runs']} succeeded (per planner and setting in "
              "report.md: success counts, lengths against the best found, anytime costs)")
    print(f"results: {result.directory}")
    print(f"database: {result.database}  (open in Planner Arena: plannerarena.org)" if result.database is not None
          else "database: none (no experiment finished)")
    if result.report:
        print("report:", *(result.report[k] for k in ("markdown", "csv") if k in result.report))
    if result.plots:
        print(f"plots: {result.directory / 'plots'} ({len(result.plots)} PNG)")
    if result.broken_logs:
        print(f"re-ran {len(result.broken_logs)} unreadable log(s), kept in {result.directory / 'logs' / 'broken'}: "
              + ", ".join(p.name for p in result.broken_logs))


def main(argv: Sequence[str] | None = None) -> int:
    """Stand-alone entry point: parse ``argv`` and :func:`run` the campaign; returns the exit code."""
    return run(build_parser().parse_args(argv))
