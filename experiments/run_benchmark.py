#!/usr/bin/env python
"""Run a benchmark campaign: dimension-RRT vs OMPL planners (Table 4 + anytime). See experiments/README.md.

Thin wrapper: the logic is ``tpee_ompl.bench.campaign`` (``run_campaign``, ``build_parser``, ``main``).
"""

import gc
import sys

from tpee_ompl.bench.campaign import main

if __name__ == "__main__":
    code = main(sys.argv[1:])
    gc.collect()
    sys.exit(code)
