"""What every ``tpee-ompl`` command group shares: the user-facing error, argument types, model options.

Exit codes (:func:`tpee_ompl.cli.main.main`): **2** for a usage error -- argparse's own, or a
:class:`CliError` raised while the arguments are checked, before any work starts (a bad value, a
missing input file, an output that exists without ``--force``); **1** for a runtime error -- anything
raised once the work has started (a damaged library or query file, a model mismatch, a planner
failure, an optional extra that is not installed: an ImportError saying what to install, an unexpected
exception).  Either way: one line on stderr, no traceback (``-v`` adds it).

:func:`argument` turns a ValueError raised while one argument is checked into a :class:`CliError`
naming it; :func:`check_input_file` and :func:`check_output` are the input- and output-file checks.
"""

from __future__ import annotations

import argparse
import contextlib
import inspect
import math
import re
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

if TYPE_CHECKING:
    from ..model.wearer_arm import WearerArm

from ..validation import MAX_COUNT, MAX_SECONDS

__all__ = [
    "MAX_COUNT",
    "MAX_SECONDS",
    "CliError",
    "count",
    "Parser",
    "add_force_arg",
    "angle",
    "add_model_args",
    "argument",
    "check_input_file",
    "check_library_model",
    "check_model_args",
    "check_output",
    "default_of",
    "finite",
    "index",
    "int_between",
    "load_robot",
    "nonempty",
    "numpy_seed",
    "on_postures",
    "positive_float",
    "positive_int",
    "seed",
    "seconds",
    "sector",
]

POSTURE_SNAP = 1e-3
"""Radians. A ``--start``/``--goal`` whose DOF1/DOF2 lie this close to its sector's Table 1 posture is taken as at
it (the values ``plan`` prints, 4 decimals, are 5e-5 rad off; the planners want the posture to 1e-6)."""

class CliError(Exception):
    """A usage error: printed as one line, exit code 2 (the argument or file named in the message)."""


@contextlib.contextmanager
def argument(name: str) -> Iterator[None]:
    """Check one argument: a ValueError raised inside becomes a :class:`CliError` starting with ``name``."""
    try:
        yield
    except CliError:
        raise
    except ValueError as exc:
        raise CliError(f"{name}: {exc}") from None


class Parser(argparse.ArgumentParser):
    """An ``ArgumentParser`` whose usage errors are ONE line on stderr (exit 2), naming the argument.

    argparse's own ``error`` prints the whole usage block first; a user (or a script reading stderr)
    should see only what was wrong.  Subparsers made from it are of this class too.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        # negative numbers in exponent notation (``--target 0 0 -1e6``) are values, not options
        self._negative_number_matcher = re.compile(r"^-(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?$")

    def error(self, message: str) -> NoReturn:  # noqa: D102 (argparse override)
        self.exit(2, f"{self.prog}: error: {message} (see --help)\n")


# ---------------------------------------------------------------------------------------- argument types
def finite(text: str) -> float:
    """argparse type: a finite float."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"not a finite number: {text}")
    return v


def nonempty(text: str) -> str:
    """argparse type: a file name or other text that is not empty (``--resume ""`` from an unset shell variable
    must not mean "not given")."""
    if not text.strip():
        raise argparse.ArgumentTypeError("must not be empty")
    return text


def _int(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None


def _int_in(text: str, low: int, high: int | None, message: str) -> int:
    """``text`` as an int in [low, high] (no upper end when ``high`` is None), else ``message``."""
    v = _int(text)
    if v < low or (high is not None and v > high):
        raise argparse.ArgumentTypeError(f"{message}: {text}")
    return v


def positive_int(text: str) -> int:
    """argparse type: an int in [1, :data:`MAX_COUNT`]."""
    return _int_in(text, 1, MAX_COUNT, f"must be a positive integer <= {MAX_COUNT:.0e}")


def int_between(low: int, high: int) -> Callable[[str], int]:
    """argparse type: an int in [low, high], the range said when refused."""
    def parse(text: str) -> int:
        return _int_in(text, low, high, f"must be an integer in [{low}, {high}]")

    parse.__name__ = f"int_between_{low}_{high}"  # argparse names the type in some messages
    return parse


def count(text: str) -> int:
    """argparse type: an int in [0, :data:`MAX_COUNT`] (0 meaning "off" where the option says so)."""
    return _int_in(text, 0, MAX_COUNT, f"must be an integer in [0, {MAX_COUNT:.0e}]")


def index(text: str) -> int:
    """argparse type: an index >= 0 (a negative one is refused, not counted from the end)."""
    return _int_in(text, 0, None, "must be an index >= 0")


def angle(text: str) -> float:
    """argparse type: an angle in radians, within [-2 pi, 2 pi]."""
    v = finite(text)
    if abs(v) > 2 * math.pi:
        raise argparse.ArgumentTypeError(f"an angle in radians must be within [-2 pi, 2 pi]: {text}")
    return v


def seconds(text: str) -> float:
    """argparse type: a time limit in seconds, finite, > 0 and at most :data:`MAX_SECONDS`."""
    v = positive_float(text)
    if v > MAX_SECONDS:
        raise argparse.ArgumentTypeError(f"a time limit must be at most {MAX_SECONDS:g} s: {text}")
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
        return check_seed("seed", _int(text))
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc).removeprefix("seed ")) from None


def numpy_seed(text: str) -> int:
    """argparse type: a seed for numpy only (no OMPL), an integer in [0, 2**32 - 1]."""
    from ..validation import MAX_SEED

    return _int_in(text, 0, MAX_SEED, f"must be an integer in [0, {MAX_SEED}]")


def sector(text: str) -> int:
    """argparse type: a posture sector number (1-4)."""
    from ..model.sectors import check_sector

    try:
        return check_sector(_int(text))
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def default_of(func: Callable[..., Any], name: str) -> Any:
    """The default of parameter ``name`` of ``func``: a flag that feeds a function takes its default from it."""
    return inspect.signature(func).parameters[name].default


# ---------------------------------------------------------------------------------------- files
def check_input_file(path: str | Path, option: str, what: str = "file", hint: str = "") -> Path:
    """``path`` if it is an existing file; else a :class:`CliError` naming ``option`` (a usage error)."""
    p = Path(path)
    if str(path) == "":
        raise CliError(f"{option}: give a file name, not an empty string")
    if p.is_dir():
        raise CliError(f"{option} {p}: is a folder, not a {what}")
    if p.exists() and not p.is_file():
        raise CliError(f"{option} {p}: is not a regular file (a pipe or a device), not a {what}")
    if not p.is_file():
        raise CliError(f"{option} {p}: {what} not found{hint}")
    return p


def check_library_model(path: str | Path, robot: WearerArm, option: str = "--library") -> None:
    """A usage error (exit 2) when the library file at ``path`` was built for another model than ``robot``'s; a
    missing or damaged file raises its own error (a runtime one)."""
    from ..library.storage import library_model_hash

    built_for = library_model_hash(path)
    if built_for != robot.model_hash:
        raise CliError(f"{option} {path}: built for model {built_for!r}, not the loaded model {robot.model_hash!r}: "
                       "give the --urdf/--srdf it was built for, or build one for this model ('tpee-ompl library "
                       "build --urdf U --srdf S --library FILE')")


def add_force_arg(p: argparse.ArgumentParser) -> None:
    """``--force``: replace an existing output file."""
    p.add_argument("--force", action="store_true", help="replace the output file if it exists")


def check_output(path: str | Path, option: str, force: bool, suffixes: tuple[str, ...] = ()) -> Path:
    """Check an output file before any work starts (:func:`tpee_ompl.files.check_output_path`): not a
    folder, not an existing file unless ``force``, and (when given) one of ``suffixes``.  Creates nothing."""
    from ..files import check_output_path

    p = Path(path)
    try:
        check_output_path(p, force=force, what=option)
    except (ValueError, FileExistsError) as exc:
        raise CliError(str(exc)) from None
    if suffixes and p.suffix.lower() not in suffixes:
        listed = " or ".join(suffixes) if len(suffixes) <= 4 else ", ".join(suffixes[:4]) + ", ..."
        raise CliError(f"{option} {p}: give a file name ending in {listed}")
    return p


# ---------------------------------------------------------------------------------------- the model
def on_postures(start: Any, goal: Any, from_sector: int, to_sector: int) -> tuple[Any, Any, str | None]:
    """``start`` and ``goal`` (arrays of DOF1..DOF4) with DOF1/DOF2 set to their sectors' Table 1 postures when
    within :data:`POSTURE_SNAP` of them, and the usage error to raise once the other checks of ``--start``/``--goal``
    passed (None when both are at their postures; naming each that is not): a cross-sector motion starts and
    ends at the postures."""
    import numpy as np

    from ..model.sectors import posture_preset

    out, off = [], []
    for name, q, k in (("--start", start, from_sector), ("--goal", goal, to_sector)):
        q, preset = np.array(q, dtype=float), posture_preset(k)
        if np.max(np.abs(q[:2] - preset)) <= POSTURE_SNAP:
            q[:2] = preset
        else:
            off.append(f"{name}: DOF1/DOF2 ({q[0]:.4f}, {q[1]:.4f}) are not sector {k}'s posture "
                       f"({preset[0]:.6f}, {preset[1]:.6f})")
        out.append(q)
    error = "; ".join(off) + ": a cross-sector motion starts and ends at the sectors' Table 1 postures" if off else None
    return out[0], out[1], error


def add_model_args(p: argparse.ArgumentParser) -> None:
    """``--urdf`` / ``--srdf``: another wearer + arm model than the packaged one."""
    p.add_argument("--urdf", type=nonempty, default=None,
                   help="URDF of a wearer + arm model (the 4 arm joints and the muzzle link; default: the "
                        "packaged one)")
    p.add_argument("--srdf", type=nonempty, default=None, help="SRDF file with disabled collision pairs (with --urdf)")


def check_model_args(args: argparse.Namespace) -> None:
    """Usage checks of ``--urdf`` / ``--srdf`` (files exist, ``--srdf`` only with ``--urdf``)."""
    urdf, srdf = getattr(args, "urdf", None), getattr(args, "srdf", None)
    if srdf and not urdf:
        raise CliError("--srdf needs --urdf")
    if urdf:
        check_input_file(urdf, "--urdf", "URDF file")
    if srdf:
        check_input_file(srdf, "--srdf", "SRDF file")


def load_robot(args: argparse.Namespace) -> WearerArm:
    """The model the ``--urdf`` / ``--srdf`` arguments name (the packaged one by default).

    Missing files are usage errors (exit 2); a file that does not load is a runtime error (exit 1).
    """
    from ..model.wearer_arm import WearerArm

    check_model_args(args)
    if not getattr(args, "urdf", None):
        return WearerArm()
    robot = WearerArm(args.urdf, args.srdf)
    if not args.srdf and robot.always_colliding:  # the robot's warning named the pairs; the cause here is plainer
        import logging

        logging.getLogger("tpee_ompl.cli").warning("without --srdf no collision pair is disabled: give the model's "
                                                   "SRDF (it disables the pairs its links touch by design)")
    return robot
