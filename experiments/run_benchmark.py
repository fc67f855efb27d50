#!/usr/bin/env python
"""Run a benchmark campaign: dimension-RRT vs OMPL planners (Table 4 + anytime). See experiments/README.md.

Thin wrapper: the command line is ``tpee_ompl.cli.bench`` (same options as ``tpee-ompl bench``),
the campaign ``tpee_ompl.bench.campaign``.
"""

import gc
import sys

from tpee_ompl.cli.bench import main

if __name__ == "__main__":
    code = main(sys.argv[1:])
    gc.collect()
    sys.exit(code)
