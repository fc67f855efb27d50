"""Build the default cross-sector path library (``make library``).

Same options and the same refusals as ``tpee-ompl library build`` (see ``--help``): this script only
forwards its arguments to the command line (``tpee_ompl.cli.main.main``).
"""

from __future__ import annotations

import logging
import sys

from tpee_ompl.cli.main import main as cli_main


def main(argv: list[str] | None = None) -> int:
    """``tpee-ompl library build ARGV`` with progress logged at INFO level."""
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(name)s: %(message)s")
    return cli_main(["library", "build", *(sys.argv[1:] if argv is None else argv)])


if __name__ == "__main__":
    sys.exit(main())
