"""When a checker's calls on several threads stall on a busy machine, go on one thread for a while.

Pinocchio's parallel collision calls wait at barriers for every thread; when another process holds a
core, each barrier waits for a descheduled thread.  :class:`StallGuard` notices such calls and tells its
checker to use one thread for :data:`SERIAL_SECONDS`.
"""

from __future__ import annotations

import math
import time

__all__ = ["SERIAL_SECONDS", "STALL_SECONDS", "STALL_WINDOW", "StallGuard"]

STALL_SECONDS = (1e-3, 2e-5)
"""A call on several threads that takes longer than ``a + b * N`` seconds for N configurations (normal: 2-8 us
each) stalled: another process held a core, and each of the call's barriers waited for a descheduled thread.
Two planning processes on two cores made a 0.1-s solve end up to 0.5 s late that way, and each process 10 times
slower (``experiments/thread_contention.py``).  After two stalls within :data:`STALL_WINDOW` the checker uses one
thread for :data:`SERIAL_SECONDS` (a lone slow call, 1-5 ms about twice a second, is the machine's noise)."""
STALL_WINDOW = 0.1
"""Seconds within which a second stalled call makes the checker go on one thread."""
SERIAL_SECONDS = 0.5
"""How long a checker stays on one thread after stalling (then it tries its threads again)."""


class StallGuard:
    """One checker's record of its stalled calls: how many threads its next call may use."""

    def __init__(self) -> None:
        self.stalls = 0
        """Times the checker went on one thread after stalled calls."""
        self.serial_until = 0.0
        """``time.perf_counter()`` until which calls run on one thread."""
        self.last_stall = -math.inf

    def threads(self, n_threads: int) -> int:
        """Threads for the next call: ``n_threads``, or one for :data:`SERIAL_SECONDS` after stalled calls."""
        return n_threads if n_threads == 1 or time.perf_counter() >= self.serial_until else 1

    def stalled(self, t0: float, n: int) -> bool:
        """After a call on several threads started at ``t0`` over ``n`` configurations: True when it stalled
        (:data:`STALL_SECONDS`) within :data:`STALL_WINDOW` of an earlier stall, and the next calls run on one
        thread for :data:`SERIAL_SECONDS`."""
        now = time.perf_counter()
        if now - t0 <= STALL_SECONDS[0] + STALL_SECONDS[1] * n:
            return False
        last, self.last_stall = self.last_stall, now
        if now - last > STALL_WINDOW:
            return False
        self.stalls += 1
        self.serial_until = now + SERIAL_SECONDS
        return True

    def state(self) -> tuple[int, float, float]:
        """Everything the guard remembers, for :meth:`restore` (a calibration's calls must leave no trace)."""
        return self.stalls, self.serial_until, self.last_stall

    def restore(self, state: tuple[int, float, float]) -> None:
        """Put back what :meth:`state` returned."""
        self.stalls, self.serial_until, self.last_stall = state
