"""The ``tpee-ompl`` console script.

The command line's modules load OMPL, Pinocchio and Coal (about 0.3 s).  They are imported here, inside the
script's function, so that Ctrl-C in that time ends the command as it does later (exit 130 and one line, see
:mod:`tpee_ompl.cli.main`) instead of with a traceback of the interrupted import.
"""

from __future__ import annotations

import sys


def main() -> int:
    """Run ``tpee-ompl`` with the process's arguments; returns the exit code."""
    try:
        from .cli.main import main as run
    except KeyboardInterrupt:
        print("tpee-ompl: interrupted", file=sys.stderr)
        return 130
    return run()
