"""Why the library plans demos with room around the pointing system and uses absolute DMP forcing.

Builds one small library per demo-margin setting (``--per-pair`` demos per pair, same seed, so the
same draws), learns its DMPs both with eq. 13's x(g - y0) scaling and with absolute forcing, and
reports the share of raw DMP paths (closest demo, no repair) that pass the motion check on a
stored query set.  Writes ``<out>.json`` and prints the table of docs/dmp.md.

    python experiments/dmp_library_ablation.py --per-pair 10 --workers 2
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
import time
from pathlib import Path

import numpy as np

from tpee_ompl.bench.results import new_output_stem
from tpee_ompl.library import DEMO_MARGINS, DMPOptions, PathLibrary
from tpee_ompl.planning.paths import motion_is_valid, path_length
from tpee_ompl.model.queries import load_queries
from tpee_ompl.model.wearer_arm import default_robot

LADDERS = ((), (0.03,), (0.04, 0.03, 0.025), (0.05, 0.04, 0.03, 0.025))
"""Demo margins (m) around links 3-4, widest first; () = the robot's own 2 cm."""


def _label(margins: tuple[float, ...]) -> str:
    text = " / ".join(f"{m * 100:g}" for m in margins) + " cm around links 3-4" if margins else "2 cm (the robot's margin)"
    return text + (" (default)" if tuple(margins) == tuple(DEMO_MARGINS) else "")


SETTINGS = {_label(m): m for m in LADDERS}


def raw_paths(lib: PathLibrary, queries: list) -> tuple[float, float]:
    """Share of queries whose closest demonstration's DMP path passes the motion check, and the
    median length (rad) of those paths (valid or not)."""
    ok, lengths = 0, []
    for q in queries:
        k = int(lib.demo_order(q.start, q.goal, q.from_sector, q.to_sector)[0])
        path = lib.generate(q.start, q.goal, q.from_sector, q.to_sector, k, stride=lib.query_stride)
        ok += motion_is_valid(lib.robot, path)
        lengths.append(path_length(path))
    return ok / len(queries), float(np.median(lengths))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--per-pair", type=int, default=10)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--query-set", default="planning_necessary")
    ap.add_argument("--out", type=Path, default=Path("experiments/library/ablation"))
    args = ap.parse_args(argv)
    logging.basicConfig(level=logging.WARNING)
    robot = default_robot()
    queries = load_queries(args.query_set, robot)
    rows = []
    for label, margins in SETTINGS.items():
        t0 = time.perf_counter()
        lib = PathLibrary.build_default(robot, per_pair=args.per_pair, seed=args.seed, demo_margins=margins,
                                        workers=args.workers)
        build_s = time.perf_counter() - t0
        stored = {k: v for k, v in lib.build_stats.items() if k.startswith("stored")}
        for scaling in ("amplitude", "none"):
            share, length = raw_paths(lib.with_options(DMPOptions(scaling=scaling)), queries)
            rows.append({"demos": label, "margins": list(margins), "scaling": scaling, "raw_valid": share,
                         "median_length_rad": length,
                         "n_demos": len(lib), "stored": stored, "build_s": round(build_s, 1)})
            print(f"{label:45s} {scaling:9s} raw DMP valid {share:.1%}, median length {length:.3f} rad "
                  f"({len(lib)} demos, {stored})", flush=True)
    print("\n| demos planned at | eq. 13 scaling x(g - y0) | absolute forcing (S = 1) | median length, absolute (rad) |")
    print("|---|---|---|---|")
    for label in SETTINGS:
        a, n = (next(r for r in rows if r["demos"] == label and r["scaling"] == s) for s in ("amplitude", "none"))
        print(f"| {label} | {a['raw_valid']:.1%} | {n['raw_valid']:.1%} | {n['median_length_rad']:.3f} |")
    stem = new_output_stem(args.out, (".json",))  # never overwrite earlier results
    stem.with_name(stem.name + ".json").write_text(json.dumps({"query_set": args.query_set, "queries": len(queries),
                                                         "per_pair": args.per_pair, "seed": args.seed, "rows": rows}, indent=1))
    print(f"wrote {stem.with_name(stem.name + '.json')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
