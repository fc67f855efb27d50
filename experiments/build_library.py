"""Build the default cross-sector path library (``make library``).

Same options as ``tpee-ompl library build`` (see ``--help``); the logic is
:func:`tpee_ompl.cli.library.run_build`, so this script only parses and runs it.
"""

from __future__ import annotations

import logging
import sys

from tpee_ompl.cli.library import build_parser


def main(argv: list[str] | None = None) -> int:
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(name)s: %(message)s")
    args = build_parser().parse_args(["library", "build", *(sys.argv[1:] if argv is None else argv)])
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
