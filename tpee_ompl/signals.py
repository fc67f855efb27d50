"""Signals: child processes that a Ctrl-C cannot interrupt while they start; SIGTERM and SIGHUP handled like Ctrl-C.

A Ctrl-C in a terminal sends SIGINT to every process of the foreground group, children included.  A child
spawned a moment earlier is still importing (unpickling its task imports OMPL), and a KeyboardInterrupt
raised inside the bindings' import aborts it with a C++ ``terminate`` and a page of traceback.  Children
started within :func:`sigint_blocked_for_children` begin with SIGINT blocked (the signal mask survives fork
and exec); once running, each one says what SIGINT does to it with :func:`child_sigint`.  The parent's own
SIGINT is held, not lost, while the block lasts (starting a process: milliseconds), and so is a SIGTERM
handled by :func:`sigterm_as_keyboard_interrupt` (it raises when the block ends: a Dask cluster interrupted
while it started left a traceback at exit).

:func:`sigterm_as_keyboard_interrupt`: within it SIGTERM (``kill``, a cluster's scheduler) and SIGHUP (the terminal
closed, an ssh session dropped) end the work the way Ctrl-C does, so the same cleanup runs (finished logs kept, child
processes ended: a SIGHUP used to kill the command at once, leaving a library build's workers blocked for good).
All are also counted (:func:`interrupts`): Python drops an exception raised in a weakref callback or ``__del__``
(matplotlib's, while plots are drawn), so a caller asks after the work whether one came; within the block such a
dropped KeyboardInterrupt prints nothing (``sys.unraisablehook``), other dropped exceptions print as before.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from typing import Any

__all__ = ["STOP_SIGNALS", "child_sigint", "die_with_parent", "exit_reason", "interrupts", "sigint_blocked_for_children",
           "sigterm_as_keyboard_interrupt"]

STOP_SIGNALS: tuple[signal.Signals, ...] = tuple(getattr(signal, name) for name in ("SIGTERM", "SIGHUP")
                                                 if hasattr(signal, name))
"""The signals handled as Ctrl-C besides SIGINT (SIGHUP where the platform has it)."""

_RECEIVED: list[int] = []
"""Every SIGINT, SIGTERM or SIGHUP the handler of :func:`sigterm_as_keyboard_interrupt` was called for, in order."""
_HELD: list[int] = []
"""Non-empty while children start (:func:`sigint_blocked_for_children`): a SIGTERM or SIGHUP then waits for the
block's end."""


def interrupts() -> int:
    """How many interrupts (SIGINT, SIGTERM, SIGHUP) :func:`sigterm_as_keyboard_interrupt` has seen here: compare
    the count before and after a piece of work to know whether one came, even one whose KeyboardInterrupt Python
    dropped."""
    return len(_RECEIVED)


@contextlib.contextmanager
def sigint_blocked_for_children() -> Iterator[None]:
    """Start child processes inside this block: they begin with SIGINT blocked (POSIX main thread only; a no-op elsewhere)."""
    if not hasattr(signal, "pthread_sigmask") or threading.current_thread() is not threading.main_thread():
        yield
        return
    from multiprocessing import resource_tracker

    resource_tracker.ensure_running()  # started on a spawn's first use, it unblocks SIGINT afterwards: start it first
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    _HELD.append(0)  # (a marker: SIGTERM's handler holds its signal while this is non-empty)
    held = len(_RECEIVED)
    try:
        yield
    finally:
        _HELD.pop()
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)  # a held SIGINT is delivered here
        if len(_RECEIVED) > held and not _HELD:  # a SIGTERM or SIGHUP came while the children started
            raise KeyboardInterrupt(f"signal {_RECEIVED[-1]}")


def child_sigint(handler: Callable[[int, Any], Any] | int) -> None:
    """In a child started by :func:`sigint_blocked_for_children`: SIGINT's handler (``signal.SIG_IGN`` when the
    parent ends the child itself), then SIGINT unblocked (a pending one then goes to ``handler``, or is dropped)."""
    signal.signal(signal.SIGINT, handler)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


@contextlib.contextmanager
def sigterm_as_keyboard_interrupt() -> Iterator[None]:
    """Within the block, SIGTERM and SIGHUP (:data:`STOP_SIGNALS`) raise KeyboardInterrupt like Ctrl-C, and all are
    counted (:func:`interrupts`); main thread only, a no-op elsewhere."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum: int, frame: object) -> None:
        _RECEIVED.append(signum)
        if signum != signal.SIGINT and _HELD:  # children are starting: raised when they have (as SIGINT's mask does)
            return
        raise KeyboardInterrupt(f"signal {signum}")

    def unraisable(info: Any) -> None:  # an interrupt Python dropped (counted above): no "Exception ignored" page
        if not (isinstance(info.exc_type, type) and issubclass(info.exc_type, KeyboardInterrupt)):
            previous_hook(info)

    previous = {sig: signal.signal(sig, handler) for sig in STOP_SIGNALS}
    default_int = signal.getsignal(signal.SIGINT) is signal.default_int_handler  # (not a handler of someone else's)
    previous_int = signal.signal(signal.SIGINT, handler) if default_int else None
    previous_hook, sys.unraisablehook = sys.unraisablehook, unraisable
    try:
        yield
    finally:
        sys.unraisablehook = previous_hook
        for sig, before in previous.items():
            signal.signal(sig, before)
        if previous_int is not None:
            signal.signal(signal.SIGINT, previous_int)


def die_with_parent(parent: int) -> None:
    """In a child process: Linux delivers SIGKILL when the parent (process ``parent``) dies, so no orphan keeps
    working; exit at once when it died already, while this process started (its imports take ~1 s)."""
    if sys.platform.startswith("linux"):
        with contextlib.suppress(Exception):
            import ctypes

            ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    if os.getppid() != parent:
        os._exit(1)


def exit_reason(exitcode: int | None) -> str:
    """How a child process that sent no result ended, from its exit code: "killed by SIGKILL", ..."""
    if exitcode is not None and exitcode < 0:
        try:
            return f"killed by {signal.Signals(-exitcode).name}"
        except ValueError:
            return f"killed by signal {-exitcode}"
    return f"exited with status {exitcode} without a result"
