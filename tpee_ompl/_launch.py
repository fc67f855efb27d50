"""The ``tpee-ompl`` console script (and ``python -m tpee_ompl``).

The command line's modules load OMPL, Pinocchio and Coal (about 0.3 s).  A KeyboardInterrupt raised while a
compiled module initialises aborts the process (nanobind: ``terminate called after throwing an instance of
'nanobind::python_error'``), and one raised in a finaliser there is dropped.  So SIGINT, SIGTERM and SIGHUP are held
(blocked) while those modules load and delivered when the imports end: the command then ends as it does later
(exit 130 and one line, see :mod:`tpee_ompl.cli.main`).  SIGTERM and SIGHUP are handled as Ctrl-C from the first moment
(the command's own handler, :func:`tpee_ompl.signals.sigterm_as_keyboard_interrupt`, takes over once its work
starts).
"""

from __future__ import annotations

import signal
import sys


def _interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt


def main() -> int:
    """Run ``tpee-ompl`` with the process's arguments; returns the exit code."""
    stop = [getattr(signal, name) for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name)]  # (signals.STOP_SIGNALS)
    for sig in stop:  # SIGTERM used to end the process without a word while the modules loaded
        signal.signal(sig, _interrupt)
    held = {signal.SIGINT, *stop}
    block = hasattr(signal, "pthread_sigmask")
    try:
        previous = signal.pthread_sigmask(signal.SIG_BLOCK, held) if block else None
        try:
            from .cli.main import main as run
        finally:
            if block:
                signal.pthread_sigmask(signal.SIG_SETMASK, previous)  # a held signal is delivered here, in Python
        return run()
    except KeyboardInterrupt:  # during the imports or the argument parsing: the command's handler is not on yet
        print("tpee-ompl: interrupted", file=sys.stderr)
        return 130
