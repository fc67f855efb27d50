"""Dimension-RRT's first path against RRTConnect's, pooled over many of RRTConnect's seeds, with a bootstrap interval.

    for s in $(seq 1 20); do PYTHONPATH=. .venv/bin/python experiments/first_path.py --skip-overhead --reps 3 \\
        --queries planning_necessary --ompl-seed $s --save /tmp/fp/$s.json; done
    PYTHONPATH=. .venv/bin/python experiments/first_path_pooled.py /tmp/fp/*.json

Issue 15's bar is a median time to the first exact path no slower than RRTConnect's.  One seed of
RRTConnect gives a ratio of medians that moves by +/-5 % from seed to seed (and with the machine), so a
single figure cannot say which side of 1 the planners are.  This script pools the runs of several files
written by ``first_path.py --save`` (each a process with its own OMPL seed, both planners alternating
query by query) and prints, per query set: the pooled median of each planner, their ratio, each file's
ratio, and a 95 % interval of the pooled ratio from a bootstrap that resamples the queries (a query's
runs, over all files, stay together: the runs of one query are not independent of each other).  Runs
without a first path within the file's limit count as the limit (none did on the named sets).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections import defaultdict

from _common import summary
import numpy as np


def _fail(msg: str) -> SystemExit:
    return SystemExit(f"first_path_pooled: {msg}")


def _run_time(r: object, limit: float) -> tuple[str, int, str, float]:
    """(set, query, planner, seconds) of one run record; ValueError when it is not one ``first_path.py`` writes."""
    if not isinstance(r, dict) or r.get("planner") not in ("D", "R") or not isinstance(r.get("set"), str):
        raise ValueError(f"a run is not {{set, query, planner D or R, seconds}}: {r!r:.80}")
    q, t = r.get("query"), r.get("seconds")
    if isinstance(q, bool) or not isinstance(q, int):
        raise ValueError(f"a run's query is not an integer: {q!r}")
    t = limit if t is None else t
    if isinstance(t, bool) or not isinstance(t, (int, float)) or not 0 <= t < float("inf"):
        raise ValueError(f"a run's seconds is not a finite number >= 0 or null: {t!r}")
    return r["set"], q, r["planner"], float(t)


def load(files: list[str]) -> tuple[dict[str, dict[int, dict[str, list[float]]]], list[dict[str, float]]]:
    """Runs by set, query and planner over all files, and each file's per-set ratio of medians."""
    pooled: dict[str, dict[int, dict[str, list[float]]]] = defaultdict(lambda: defaultdict(lambda: {"D": [], "R": []}))
    per_file: list[dict[str, float]] = []
    for f in files:
        own: dict[str, dict[str, list[float]]] = defaultdict(lambda: {"D": [], "R": []})
        try:
            with open(f, encoding="utf-8") as fh:
                data = json.load(fh)
            limit, runs = float(data["meta"]["limit"]), data["runs"]
            if not isinstance(runs, list) or not runs:
                raise ValueError("no runs")
            for r in runs:
                name, q, who, t = _run_time(r, limit)
                pooled[name][q][who].append(t)
                own[name][who].append(t)
        except (OSError, ValueError, KeyError, TypeError) as e:
            raise _fail(f"{f}: not a file written by first_path.py --save ({e})") from None
        for name, v in own.items():
            if not v["D"] or not v["R"]:
                raise _fail(f"{f}: set {name} has no runs of {'dimension-RRT' if not v['D'] else 'RRTConnect'}")
        per_file.append({name: float(np.median(v["D"]) / np.median(v["R"])) for name, v in own.items()})
    return pooled, per_file


def bootstrap_ratio(by_query: dict[int, dict[str, list[float]]], draws: int, rng: np.random.Generator) -> np.ndarray:
    """Ratios of pooled medians (dimension-RRT / RRTConnect) over ``draws`` resamplings of the queries."""
    queries = sorted(by_query)
    d = [np.asarray(by_query[q]["D"]) for q in queries]
    r = [np.asarray(by_query[q]["R"]) for q in queries]
    out = np.empty(draws)
    for i in range(draws):
        pick = rng.integers(0, len(queries), len(queries))
        out[i] = np.median(np.concatenate([d[k] for k in pick])) / np.median(np.concatenate([r[k] for k in pick]))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("files", nargs="+", help="JSON files written by first_path.py --save")
    ap.add_argument("--draws", type=int, default=2000, help="bootstrap resamplings")
    ap.add_argument("--seed", type=int, default=0, help="seed of the bootstrap's resampling")
    args = ap.parse_args(argv)
    if args.draws < 100:
        ap.error(f"--draws must be at least 100, got {args.draws}")
    if len(set(map(os.path.realpath, args.files))) < len(args.files):
        ap.error("a file is given twice (its runs would count twice)")
    pooled, per_file = load(args.files)
    rng = np.random.default_rng(args.seed)
    for name, by_query in pooled.items():
        d = np.concatenate([np.asarray(v["D"]) for v in by_query.values()])
        r = np.concatenate([np.asarray(v["R"]) for v in by_query.values()])
        ratios = [f[name] for f in per_file if name in f]
        lo, hi = np.percentile(bootstrap_ratio(by_query, args.draws, rng), [2.5, 97.5])
        print(f"{name}: {len(ratios)} files, {len(by_query)} queries, {len(d)} / {len(r)} runs; pooled median "
              f"dimension-RRT {1e3 * np.median(d):.2f} ms, RRTConnect {1e3 * np.median(r):.2f} ms, ratio "
              f"{np.median(d) / np.median(r):.3f} (95 % interval over the queries {lo:.3f}-{hi:.3f}); p95 "
              f"{1e3 * np.percentile(d, 95):.1f} / {1e3 * np.percentile(r, 95):.1f} ms")
        print(f"  per file: ratio median {np.median(ratios):.3f}, range {min(ratios):.3f}-{max(ratios):.3f}, "
              f"{sum(x <= 1.0 for x in ratios)} of {len(ratios)} at or below 1")
    return 0


if __name__ == "__main__":
    sys.exit(main())
