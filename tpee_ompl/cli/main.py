"""The ``tpee-ompl`` command line: plan, aim, track, bench, library, show, animate, workspace, view.

One module per command group, each with ``register(sub, fmt)``: :mod:`.plan` (plan, aim, track),
:mod:`.pictures` (show, animate, workspace, view), :mod:`.library` (library build|query|stats) and
the bench group.  Every subcommand is one function.  Errors are one line on stderr, never a
traceback (``-v`` adds it): exit code 2 for a usage error (argparse's, or a
:class:`~tpee_ompl.cli._common.CliError` from the argument checks that run before any work), 1 for
an error at run time (a damaged input file, a model mismatch, a failure, a missing optional extra: an
ImportError saying what to install, anything unexpected),
130 when interrupted (Ctrl-C, or SIGTERM or SIGHUP, which every command handles as Ctrl-C), 141 without a word when
the reader of its output went away (``tpee-ompl plan ... | head -1``), as a command killed by SIGPIPE.
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import logging
import os
import select
import sys
import traceback
from collections.abc import Iterable, Iterator, Sequence
from typing import Any, TextIO

from .._version import __version__
from ..signals import interrupts, sigterm_as_keyboard_interrupt
from ._common import CliError, Parser
from .bench import register as register_bench
from .library import register as register_library
from .pictures import register as register_pictures
from .plan import register as register_plan

__all__ = ["get_argument_parser", "main"]

DESCRIPTION = "The tpee-ompl command line: plan, aim, track, bench, library, show, animate, workspace, view."
"""The parser's description (the module docstring's first line; docstrings are gone under ``python -OO``)."""


def get_argument_parser() -> argparse.ArgumentParser:
    """The full ``tpee-ompl`` argument parser."""
    parser = Parser(prog="tpee-ompl", description=DESCRIPTION)
    parser.add_argument("-v", "--verbose", action="store_true", help="log at INFO level")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")  # required: main() says so after other errors
    fmt = argparse.RawDescriptionHelpFormatter
    for register in (register_plan, register_pictures, register_bench, register_library):
        register(sub, fmt)
    return parser


def _lower_level(record: logging.LogRecord) -> bool:
    record.lowlevel = record.levelname.lower()
    return True


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``tpee-ompl``; returns the exit code."""
    parser = get_argument_parser()
    args, extra = parser.parse_known_args(argv)
    command = _command_parser(parser, args)
    if extra:  # said by the (sub)command that was given them, as its other usage errors
        command.error(f"unrecognized arguments: {' '.join(extra)}")
    if args.command is None:
        parser.error("the following arguments are required: COMMAND")
    args.prog = command.prog  # "tpee-ompl library query": who says an error or an interruption
    # a warning reads like the command's errors ("tpee-ompl: warning: ..."); -v adds the level and the logger's name
    said = "%(levelname)s %(name)s: %(message)s" if args.verbose else "tpee-ompl: %(lowlevel)s: %(message)s"
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING, format=said)
    for handler in logging.getLogger().handlers:
        handler.addFilter(_lower_level)
    seen = interrupts()
    try:
        with sigterm_as_keyboard_interrupt():  # kill / a scheduler: the same cleanup as Ctrl-C (temporary files, workers)
            stdout = sys.stdout
            if stdout is not None:
                sys.stdout = _NamedStdout(stdout)
            try:
                code = int(args.func(args) or 0)
                sys.stdout.flush()  # a closed pipe shows here, not in the interpreter's own flush at exit
            finally:  # in here: an interrupt during it is said like any other (it printed a traceback, or exit 0)
                if isinstance(sys.stdout, _NamedStdout):
                    sys.stdout = stdout
                gc.collect()  # break si <-> Python checker cycles before exit (nanobind leak warnings otherwise)
            if interrupts() > seen and code != 130:  # its KeyboardInterrupt was dropped (raised in a weakref callback)
                raise KeyboardInterrupt
            return code
    except BrokenPipeError as exc:
        if _stdout_gone():
            return 141
        return _report(args, exc)  # another pipe (a worker's): an error like any other
    except Exception as exc:  # noqa: BLE001 (the last resort: one line, never a traceback without -v)
        if interrupts() > seen:  # the interrupt came back as another error (an ImportError of an import it stopped)
            print(f"{args.prog}: interrupted", file=sys.stderr)
            return 130
        return _report(args, exc)
    except KeyboardInterrupt:
        print(f"{args.prog}: interrupted", file=sys.stderr)
        return 130


class _NamedStdout:
    """``sys.stdout`` while a command runs: a write or flush that fails (``> /dev/full``: no space left on device)
    raises an OSError saying it was standard output; a closed pipe's BrokenPipeError passes unchanged (exit 141)."""

    def __init__(self, stream: TextIO) -> None:
        self._stream = stream

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)

    def write(self, text: str) -> int:
        with self._named():
            return self._stream.write(text)

    def writelines(self, lines: Iterable[str]) -> None:
        with self._named():
            self._stream.writelines(lines)

    def flush(self) -> None:
        with self._named():
            self._stream.flush()

    @staticmethod
    @contextlib.contextmanager
    def _named() -> Iterator[None]:
        try:
            yield
        except BrokenPipeError:
            raise
        except OSError as exc:
            raise OSError(f"cannot write to standard output: {exc.strerror or exc}") from exc


def _command_parser(parser: argparse.ArgumentParser, args: argparse.Namespace) -> argparse.ArgumentParser:
    """The parser of the innermost (sub)command ``args`` came through (``tpee-ompl library build``'s for it)."""
    while parser._subparsers is not None:  # noqa: SLF001 (argparse keeps its subparsers there)
        action = parser._subparsers._group_actions[0]  # noqa: SLF001
        name = getattr(args, action.dest, None)
        if name not in action.choices:
            break
        parser = action.choices[name]
    return parser


def _report(args: argparse.Namespace, exc: Exception) -> int:
    """Say ``exc`` in one line on stderr (its traceback first with ``-v``); the exit code."""
    if args.verbose:
        traceback.print_exception(exc)
    code, message = _describe(exc)
    print(f"{args.prog}: error: {message}", file=sys.stderr)
    return code


def _stdout_gone() -> bool:
    """True when standard output is a pipe whose reader went away (poll says POLLERR); it is then pointed at
    /dev/null, so that nothing fails again at exit."""
    try:
        fd = sys.stdout.fileno()
        poller = select.poll()
        poller.register(fd, select.POLLOUT)
        gone = any(events & select.POLLERR for _, events in poller.poll(0))
        if gone:
            os.dup2(os.open(os.devnull, os.O_WRONLY), fd)
        return gone
    except (OSError, ValueError, AttributeError):  # no file descriptor (redirected in-process), no poll
        return False


def _describe(exc: Exception) -> tuple[int, str]:
    """Exit code and one-line message for an exception a command raised."""
    if isinstance(exc, CliError):
        return 2, str(exc)
    if isinstance(exc, ImportError):  # an optional extra is missing (the message says what to install): the
        return 1, str(exc)  # arguments were right, the installation lacks it
    if isinstance(exc, KeyError) and exc.args:
        return 1, str(exc.args[0])
    if isinstance(exc, (ValueError, OSError, RuntimeError)):
        message = str(exc) or type(exc).__name__
    else:
        message = f"unexpected {type(exc).__name__}: {exc} (run with -v for the traceback)"
    return 1, " ".join(message.split())  # one line, whatever the exception's text


if __name__ == "__main__":
    sys.exit(main())
