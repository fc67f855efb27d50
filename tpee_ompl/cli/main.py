"""The ``tpee-ompl`` command line: plan, aim, bench, library, track, show, animate, view.

One module per command group, each with ``register(sub, fmt)``: :mod:`.plan` (plan, aim, track),
:mod:`.pictures` (show, animate, workspace, view), :mod:`.library` (library build|query|stats) and
the bench group.  Every subcommand is one function; errors from bad input are printed as one line
on stderr with exit code 2, never a traceback.
"""

from __future__ import annotations

import argparse
import gc
import logging
import sys
from collections.abc import Sequence

from ._common import CliError, Parser
from .bench import register as register_bench
from .library import register as register_library
from .pictures import register as register_pictures
from .plan import register as register_plan

__all__ = ["get_argument_parser", "main"]


def get_argument_parser() -> argparse.ArgumentParser:
    """The full ``tpee-ompl`` argument parser."""
    parser = Parser(prog="tpee-ompl", description=__doc__.split("\n")[0])
    parser.add_argument("-v", "--verbose", action="store_true", help="log at INFO level")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    fmt = argparse.RawDescriptionHelpFormatter
    for register in (register_plan, register_pictures, register_bench, register_library):
        register(sub, fmt)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``tpee-ompl``; returns the exit code."""
    parser = get_argument_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
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
