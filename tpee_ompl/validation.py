"""Small argument checks shared by every options dataclass and public entry point.

Each returns the value in its canonical Python type or raises ``ValueError`` naming the argument,
so a bad setting is refused with one clear line instead of a crash deep in the bindings.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from collections.abc import Mapping
from typing import Any, Literal, TypeVar, overload

import numpy as np

__all__ = ["MAX_COUNT", "MAX_JOINT_VALUE", "MAX_SECONDS", "MAX_SEED", "MOTION_VALIDATORS", "as_config_batch",
           "as_float_array", "check_bool", "check_int", "check_name", "check_number", "check_seed", "check_type",
           "resolve_options", "sub_seed"]


_Options = TypeVar("_Options")
_T = TypeVar("_T")


def resolve_options(cls: type[_Options], options: _Options | None, overrides: Mapping[str, Any]) -> _Options:
    """``options`` (``cls()``'s defaults if None) with keyword overrides applied (validated by ``cls``); an options
    object of another class is a ValueError, an unknown override a TypeError."""
    if options is None:
        options = cls()
    elif not isinstance(options, cls):
        raise ValueError(f"options must be a {cls.__name__}, got {type(options).__name__}")
    return dataclasses.replace(options, **overrides) if overrides else options


@overload
def check_int(name: str, value: Any, *, minimum: int | None = ..., maximum: int | None = ...,
              optional: Literal[False] = ...) -> int: ...
@overload
def check_int(name: str, value: Any, *, minimum: int | None = ..., maximum: int | None = ...,
              optional: bool) -> int | None: ...
def check_int(name: str, value: Any, *, minimum: int | None = None, maximum: int | None = None,
              optional: bool = False) -> int | None:
    """``value`` as an int (a bool is refused), within [minimum, maximum]; None passes when ``optional``."""
    if value is None and optional:
        return None
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ValueError(f"{name} must be {'None or ' if optional else ''}an integer, got {value!r}")
    v = int(value)
    if (minimum is not None and v < minimum) or (maximum is not None and v > maximum):
        bounds = f">= {minimum}" if maximum is None else f"<= {maximum}" if minimum is None else f"in [{minimum}, {maximum}]"
        raise ValueError(f"{name} must be an integer {bounds}, got {value!r}")
    return v


@overload
def check_number(name: str, value: Any, *, low: float | None = ..., high: float | None = ...,
                 low_open: bool = ..., high_open: bool = ..., optional: Literal[False] = ...) -> float: ...
@overload
def check_number(name: str, value: Any, *, low: float | None = ..., high: float | None = ...,
                 low_open: bool = ..., high_open: bool = ..., optional: bool) -> float | None: ...
def check_number(name: str, value: Any, *, low: float | None = None, high: float | None = None,
                 low_open: bool = False, high_open: bool = False, optional: bool = False) -> float | None:
    """``value`` as a finite float (a bool is refused) within the given bounds; None passes when ``optional``."""
    if value is None and optional:
        return None
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(float(value)):
        raise ValueError(f"{name} must be {'None or ' if optional else ''}a finite number, got {value!r}")
    v = float(value)
    if low is not None and (v <= low if low_open else v < low) or high is not None and (v >= high if high_open else v > high):
        lo = "" if low is None else ("(" if low_open else "[") + f"{low:g}"
        hi = "" if high is None else f"{high:g}" + (")" if high_open else "]")
        interval = f"in {lo}, {hi}" if low is not None and high is not None else (f"> {low:g}" if low_open else f">= {low:g}") if high is None else (f"< {high:g}" if high_open else f"<= {high:g}")
        raise ValueError(f"{name} must be a number {interval}, got {value!r}")
    return v


def check_bool(name: str, value: Any) -> bool:
    """``value`` if it is a bool (or numpy bool)."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def check_type(name: str, value: Any, cls: type[_T]) -> _T:
    """``value`` if it is a ``cls`` (a robot, a DMP, options), else ValueError naming the argument and the type given."""
    if not isinstance(value, cls):
        raise ValueError(f"{name} must be a {cls.__name__}, got {type(value).__name__}")
    return value


def check_name(name: str, value: Any) -> str:
    """``value`` if it is a non-empty string without control characters (a planner's name with a line break split
    its line in OMPL's benchmark log, which ``ompl_benchmark_statistics`` then could not read)."""
    if not isinstance(value, str) or not value:
        raise ValueError(f"{name} must be a non-empty string, got {value!r}")
    if not value.isprintable():
        raise ValueError(f"{name} must be printable text (no line breaks, tabs or other control characters), "
                         f"got {value!r}")
    return value


def as_float_array(x: object, what: str) -> np.ndarray:
    """``x`` as a float array, raising ValueError (naming ``what``) for non-numeric input.

    Complex numbers (numpy would drop the imaginary part with a warning), strings (numpy would parse
    ``"1"`` as 1.0) and dates are refused, not coerced; booleans and integers become floats (an integer too
    large for a float is refused too).
    """
    try:
        a = np.asarray(x)
        if a.dtype.kind in "cUSMmV":
            raise TypeError(f"{a.dtype} values are not real numbers")
        return a.astype(float, copy=False)
    except (TypeError, ValueError, OverflowError) as exc:
        raise ValueError(f"{what} must be real numbers, got {x!r} ({exc})"[:400]) from exc


def as_config_batch(Q: np.ndarray, nq: int) -> np.ndarray:
    """Q as a float array of shape (N, nq) (one row per configuration), or raise ValueError."""
    if type(Q) is np.ndarray and Q.dtype == np.float64 and Q.ndim == 2 and Q.shape[1] == nq and np.isfinite(Q).all():
        return Q  # the planners' own batches: one test instead of the checks below
    Q = as_float_array(Q, "configurations")
    if Q.ndim == 1:
        Q = Q[None, :]
    if Q.ndim != 2 or Q.shape[1] != nq:
        raise ValueError(f"configurations must have shape (N, {nq}); got {Q.shape}")
    bad = ~np.all(np.isfinite(Q), axis=1)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(f"configurations contain NaN or inf: row {k} is {Q[k]}")
    return Q


MAX_COUNT = 10**7
"""Largest count an argument may ask for (samples, frames, steps, sample caps): more is refused, not attempted
(a typo must not allocate exabytes or run for a year)."""
MAX_JOINT_VALUE = 1e3
"""Largest |joint value| (rad, or m for a prismatic joint) taken anywhere: no joint travels further, and a motion
across more could not be checked state by state."""
MAX_SECONDS = 86_400.0
"""Longest time limit (s) a planning run may be given: a day.  OMPL turns a budget into a time point, and
a far larger one (1e10 s) overflows it into the past: every run stopped at once as a TIMEOUT."""

MAX_SEED = 2**32 - 1
"""Largest accepted seed (OMPL's ``RNG.setSeed`` takes an unsigned integer; numpy's generators accept it too)."""

MOTION_VALIDATORS = ("batched", "discrete", "certified", "dense")
"""The motion validators a setup can have (``make_simple_setup(motion_validator=...)``, a campaign's checkers):
batched Pinocchio calls screened by clearance balls, OMPL's ``DiscreteMotionValidator``, clearance certificates
(a few Coal distances per motion), or the batched one checking every state (``dense``: the same verdicts as
``batched``, to measure the screening).  Here, below both, so that the campaign's configuration reads them
without importing OMPL."""


def sub_seed(*parts: int) -> int:
    """A seed in [0, 2**32) derived from integer ``parts`` (``np.random.SeedSequence``): independent
    streams for each (campaign seed, query, planner, budget) or (planner seed, run) from one seed."""
    return int(np.random.SeedSequence([int(p) for p in parts]).generate_state(1)[0])


def check_seed(name: str, value: Any) -> int:
    """A seed for OMPL's ``RNG.setSeed`` and numpy: an integer in [1, 2**32 - 1].

    0 is refused: OMPL ignores it with a warning ("seed cannot be 0") and would run unseeded.
    """
    return check_int(name, value, minimum=1, maximum=MAX_SEED)
