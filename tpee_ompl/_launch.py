"""The ``tpee-ompl`` console script (and ``python -m tpee_ompl``).

The command line's modules load OMPL, Pinocchio and Coal (about 0.3 s).  They are imported here, inside the
script's function, so that Ctrl-C in that time ends the command as it does later (exit 130 and one line, see
:mod:`tpee_ompl.cli.main`) instead of with a traceback of the interrupted import; SIGTERM does the same from
the first moment (the command's own handler, :func:`tpee_ompl.signals.sigterm_as_keyboard_interrupt`, takes
over once its work starts).
"""

from __future__ import annotations

import signal
import sys


def _interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt


def main() -> int:
    """Run ``tpee-ompl`` with the process's arguments; returns the exit code."""
    signal.signal(signal.SIGTERM, _interrupt)  # it used to end the process without a word while the modules loaded
    try:
        from .cli.main import main as run

        return run()
    except KeyboardInterrupt:  # during the imports or the argument parsing: the command's handler is not on yet
        print("tpee-ompl: interrupted", file=sys.stderr)
        return 130
