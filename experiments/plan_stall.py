"""What ``tpee-ompl plan``'s stall rule saves: the library planner stopped after 1000 samples without a
shorter path against the same planner given the whole time, over the 12 ordered sector pairs.

    PYTHONPATH=. .venv/bin/python experiments/plan_stall.py            # ~40 s

Runs ``tpee-ompl plan --from I --to J --json`` (default planner and ``--stall``) and the same with
``--stall 0 --time 2``, for every ordered sector pair (the first stored query of each), and prints
per pair the stalled run's time and length against the 2 s run's, then the medians and maxima.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys

from _common import summary


def _plan(i: int, j: int, *extra: str) -> dict:
    out = subprocess.run([sys.executable, "-m", "tpee_ompl.cli", "plan", "--from", str(i), "--to", str(j), "--json", *extra],
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def main(argv: list[str] | None = None) -> None:
    argparse.ArgumentParser(description=summary(__doc__)).parse_args(argv)  # --help; no options
    times, excess = [], []
    for i in range(1, 5):
        for j in range(1, 5):
            if i == j:
                continue
            stalled, full = _plan(i, j), _plan(i, j, "--stall", "0", "--time", "2")
            t, ratio = stalled["time_s"], stalled["length_rad"] / full["length_rad"] - 1.0
            times.append(t)
            excess.append(ratio)
            print(f"{i}->{j}: stalled {t:.3f} s, length {stalled['length_rad']:.4f}; 2 s: {full['length_rad']:.4f} ({100 * ratio:+.2f} %)",
                  flush=True)
    print(f"stalled run: median {statistics.median(times):.3f} s (max {max(times):.3f} s); length above the 2 s run's: "
          f"median {100 * statistics.median(excess):.2f} % (max {100 * max(excess):.2f} %)")


if __name__ == "__main__":
    main()
