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
import sys
from collections.abc import Sequence
from pathlib import Path

from ..bench.config import CHECKERS, CampaignConfig
from ._common import Parser

__all__ = ["DESCRIPTION", "EXAMPLE", "add_arguments", "build_parser", "config_from_args", "main", "register", "run"]

DESCRIPTION = "Benchmark dimension-RRT against OMPL planners (ompl.tools.Benchmark)."
EXAMPLE = "example:\n  tpee-ompl bench --max-queries 24 --samples 500 2500 --anytime 0.1 0.5 --workers 2"


def _default(name: str):
    """The default of a :class:`CampaignConfig` field (tuples as lists, as argparse gives them)."""
    f = next(f for f in dataclasses.fields(CampaignConfig) if f.name == name)
    v = f.default_factory() if f.default is dataclasses.MISSING else f.default
    return list(v) if isinstance(v, tuple) else v


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Add the campaign, executor and resume options to ``p``."""
    p.add_argument("--queries", default=_default("queries"), help="query-set name or JSON file (default: %(default)s)")
    p.add_argument("--name", default=None, help="results folder suffix (default: the query-set name)")
    p.add_argument("--samples", type=int, nargs="*", default=_default("sample_caps"),
                   help="sample/iteration caps of the Table-4 comparison (default: %(default)s); none to skip")
    p.add_argument("--anytime", type=float, nargs="*", default=_default("anytime_budgets"),
                   help="time budgets (s) of the anytime comparison (default: %(default)s); none to skip")
    p.add_argument("--planners", nargs="+", default=_default("iteration_planners"),
                   help="iteration-matched planners; the first is compared with the second (default: %(default)s)")
    p.add_argument("--anytime-planners", nargs="+", default=_default("anytime_planners"), help="(default: %(default)s)")
    p.add_argument("--checkers", nargs="+", default=_default("checkers"), choices=CHECKERS,
                   help="motion validators; the first is the headline (default: %(default)s)")
    p.add_argument("--alt-checker-queries", type=int, default=_default("alt_checker_queries"),
                   help="run the non-headline validators on the first k queries only (default: all)")
    p.add_argument("--alt-checker-samples", type=int, nargs="+", default=_default("alt_checker_caps"),
                   help="caps for the non-headline validators (default: all --samples)")
    p.add_argument("--anytime-queries", type=int, default=_default("anytime_queries"),
                   help="anytime comparison on the first k queries only")
    p.add_argument("--max-queries", type=int, default=_default("max_queries"),
                   help="use N queries, round-robin over the ordered sector pairs")
    p.add_argument("--runs", type=int, default=_default("runs"), help="runs per planner per experiment (default: %(default)s)")
    p.add_argument("--workers", type=int, default=_default("workers"),
                   help="worker processes, one fresh process per query; 0 = in this process (default: %(default)s)")
    p.add_argument("--seed", type=int, default=_default("seed"),
                   help="campaign seed; query k's process uses seed + k (default: %(default)s)")
    p.add_argument("--max-time", type=float, default=_default("max_time"), help="safety limit per iteration-capped run, s")
    p.add_argument("--out", default=_default("out"), help="parent folder of the timestamped results folder")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    g = p.add_argument_group("executor (default: local process pool of --workers)")
    g.add_argument("--dask", metavar="local|tcp://HOST:PORT", default=None,
                   help="run the queries as Dask tasks: 'local' starts a LocalCluster here, an address uses that "
                        "scheduler (needs the dask extra: pip install 'tpee_ompl[dask]')")
    g.add_argument("--scheduler", metavar="tcp://HOST:PORT", default=None, help="same as --dask tcp://HOST:PORT")
    g.add_argument("--dask-workers", type=int, default=2, help="workers of --dask local (default: %(default)s)")
    g.add_argument("--retries", type=int, default=2, help="Dask retries of a task that raises (default: %(default)s)")
    p.add_argument("--resume", metavar="DIR", default=None,
                   help="finish an interrupted campaign in DIR: run only its missing experiments (configuration "
                        "from DIR/campaign.json; the other campaign options are ignored)")


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
    """A :class:`CampaignConfig` from parsed arguments."""
    name = args.name or Path(args.queries).stem
    return CampaignConfig(
        name=name,
        queries=args.queries,
        sample_caps=tuple(args.samples or ()),
        iteration_planners=tuple(args.planners),
        checkers=tuple(args.checkers),
        alt_checker_queries=args.alt_checker_queries,
        alt_checker_caps=tuple(args.alt_checker_samples) if args.alt_checker_samples else None,
        anytime_budgets=tuple(args.anytime or ()),
        anytime_planners=tuple(args.anytime_planners),
        anytime_queries=args.anytime_queries,
        max_queries=args.max_queries,
        runs=args.runs,
        workers=args.workers,
        seed=args.seed,
        out=args.out,
        max_time=args.max_time,
    )


def run(args: argparse.Namespace) -> int:
    """Run (or ``--resume``) a campaign from parsed arguments; print the ratio table and where the files are.

    Returns the exit code: 0, 2 for a bad configuration (one line on stderr), 130 when interrupted.
    """
    from ..bench.campaign import resume_campaign, run_campaign
    from ..bench.executors import make_executor

    logging.basicConfig(level=logging.INFO, format="%(message)s")
    try:
        config = config_from_args(args)
        if args.resume and not (Path(args.resume) / "campaign.json").is_file():
            raise ValueError(f"--resume {args.resume}: no campaign.json there")
        executor = make_executor(config.workers, dask=args.scheduler or args.dask, dask_workers=args.dask_workers,
                                 retries=args.retries)
    except (ValueError, ImportError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    try:
        if args.resume:
            result = resume_campaign(args.resume, executor=executor, workers=config.workers,
                                     progress_bar=not args.no_progress)
        else:
            result = run_campaign(config, executor=executor, progress_bar=not args.no_progress)
    except KeyboardInterrupt:  # a second Ctrl-C while the database was built
        print("interrupted; finished logs are kept: finish the campaign with --resume DIR", file=sys.stderr)
        return 130
    if result.report.get("markdown_text"):
        print(result.report["markdown_text"])
    print(f"results: {result.directory}")
    print(f"database: {result.database}  (open in Planner Arena: plannerarena.org)")
    if result.report:
        print(f"report: {result.report.get('markdown')}  {result.report.get('csv')}")
    if result.plots:
        print(f"plots: {result.directory / 'plots'} ({len(result.plots)} PNG)")
    if result.skipped_logs:
        print(f"skipped {len(result.skipped_logs)} corrupt log(s): " + ", ".join(p.name for p in result.skipped_logs))
    if result.interrupted:
        print("campaign was interrupted: the database holds the finished experiments only; "
              f"finish it with --resume {result.directory}")
        return 130
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Stand-alone entry point: parse ``argv`` and :func:`run` the campaign; returns the exit code."""
    return run(build_parser().parse_args(argv))
