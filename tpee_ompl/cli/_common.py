"""What every ``tpee-ompl`` command group shares: the user-facing error, argument types, model options.

A command raises :class:`CliError` (or ValueError, FileNotFoundError, ...) with a one-line message;
:func:`tpee_ompl.cli.main.main` prints it on stderr and exits with code 2.
"""

from __future__ import annotations

import argparse
import inspect
import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, NoReturn

if TYPE_CHECKING:
    from ..model.wearer_arm import WearerArm

__all__ = [
    "CliError",
    "Parser",
    "seed",
    "add_model_args",
    "default_of",
    "finite",
    "load_robot",
    "positive_float",
    "positive_int",
    "sector",
]


class CliError(Exception):
    """A user-facing error: printed as one line, exit code 2."""


class Parser(argparse.ArgumentParser):
    """An ``ArgumentParser`` whose usage errors are ONE line on stderr (exit 2), naming the argument.

    argparse's own ``error`` prints the whole usage block first; a user (or a script reading stderr)
    should see only what was wrong.  Subparsers made from it are of this class too.
    """

    def error(self, message: str) -> NoReturn:  # noqa: D102 (argparse override)
        self.exit(2, f"{self.prog}: error: {message} (see --help)\n")


# ---------------------------------------------------------------------------------------- argument types
def finite(text: str) -> float:
    """argparse type: a finite float."""
    v = float(text)
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"not a finite number: {text}")
    return v


def positive_int(text: str) -> int:
    """argparse type: an int > 0."""
    v = int(text)
    if v <= 0:
        raise argparse.ArgumentTypeError(f"must be a positive integer: {text}")
    return v


def positive_float(text: str) -> float:
    """argparse type: a finite float > 0."""
    v = finite(text)
    if v <= 0:
        raise argparse.ArgumentTypeError(f"must be > 0: {text}")
    return v


def seed(text: str) -> int:
    """argparse type: a seed for OMPL and numpy, an integer in [1, 2**32 - 1] (OMPL ignores 0)."""
    from ..validation import check_seed

    try:
        return check_seed("seed", int(text))
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc).removeprefix("seed ")) from None


def sector(text: str) -> int:
    """argparse type: a posture sector number (1-4)."""
    from ..model.sectors import check_sector

    try:
        return check_sector(int(text))
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def default_of(func: Callable[..., Any], name: str) -> Any:
    """The default of parameter ``name`` of ``func``: a flag that feeds a function takes its default from it."""
    return inspect.signature(func).parameters[name].default


# ---------------------------------------------------------------------------------------- the model
def add_model_args(p: argparse.ArgumentParser) -> None:
    """``--urdf`` / ``--srdf``: another wearer + arm model than the packaged one."""
    p.add_argument("--urdf", default=None, help="URDF file (default: the packaged wearer + arm)")
    p.add_argument("--srdf", default=None, help="SRDF file with disabled collision pairs (with --urdf)")


def load_robot(args: argparse.Namespace) -> WearerArm:
    """The model the ``--urdf`` / ``--srdf`` arguments name (the packaged one by default)."""
    from ..model.wearer_arm import WearerArm

    if getattr(args, "srdf", None) and not getattr(args, "urdf", None):
        raise CliError("--srdf needs --urdf")
    return WearerArm(args.urdf, args.srdf) if getattr(args, "urdf", None) else WearerArm()
