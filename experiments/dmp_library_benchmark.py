"""Benchmark the DMP path library on fresh planning-necessary queries (figures for issue 6).

1. ``--per-pair`` queries per ordered sector pair from :func:`tpee_ompl.planning.query_generation.generate_queries`
   (planning-necessary regions; seeds differ from the library's build seed), drawn in
   ``--workers`` processes.
2. Every query through :meth:`PathLibrary.query` (validation, repair, dimension-RRT fallback) in this
   process alone, so the timings are not disturbed: :func:`tpee_ompl.library.evaluation.benchmark_queries`.
3. The same queries planned by dimension-RRT at ``--reference-samples`` samples (workers), for the
   path-length ratio.

Pairs with too few planning-necessary draws are filled by the generator with other queries from the
same regions; each row says whether its straight motion collides (``planning_necessary``), and the
summary reports all queries and the planning-necessary ones separately.

Writes ``<out>.csv`` (one row per query) and ``<out>.json`` (summary + parameters + hardware).

    python experiments/dmp_library_benchmark.py --per-pair 50 --workers 2
"""

from __future__ import annotations

import argparse
import csv
import json
import logging
import os
import platform
import signal
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from pathlib import Path

import numpy as np

from tpee_ompl.bench.results import new_output_stem
from tpee_ompl.library import PathLibrary, benchmark_queries, dimension_rrt_planner
from tpee_ompl.planning.paths import path_length
from tpee_ompl.resources import default_library_path

log = logging.getLogger("dmp_library_benchmark")


def _gen_queries(n_per_pair: int, seed: int) -> list[dict]:
    from tpee_ompl.model.wearer_arm import default_robot
    from tpee_ompl.planning.query_generation import generate_queries

    qs, _ = generate_queries(default_robot(), n_per_pair=n_per_pair, seed=seed)
    return [q.to_dict() for q in qs]


def _reference(items: list[tuple[int, list[float], list[float], int, int]], samples: int, seed: int) -> list[tuple[int, float]]:
    from tpee_ompl.model.wearer_arm import default_robot

    plan = dimension_rrt_planner(default_robot(), max_samples=samples, seed=seed)
    out = []
    for qid, start, goal, i, j in items:
        W = plan(np.array(start), np.array(goal), i, j)
        out.append((qid, path_length(W) if W is not None else float("nan")))
    return out


def _summary(rows: list[dict]) -> dict:
    def stats(key: str, sel: list[dict]) -> dict:
        v = np.array([r[key] for r in sel], dtype=float) * 1e3
        return {"median_ms": float(np.median(v)), "p95_ms": float(np.percentile(v, 95)), "mean_ms": float(v.mean())}

    def block(sel: list[dict]) -> dict:
        n = len(sel)
        ratio = np.array([r.get("length_ratio", np.nan) for r in sel], dtype=float)
        outcomes = {k: sum(r["outcome"] == k for r in sel) for k in ("dmp", "repaired", "fallback", "failed")}
        return {
            "queries": n,
            "query_time": stats("query_s", sel),
            "generation_time": stats("generation_s", sel),
            "raw_dmp_valid_share": sum(r["raw_valid"] for r in sel) / n,
            "outcomes": outcomes,
            "fallback_share": outcomes["fallback"] / n,
            "length_ratio_median": float(np.nanmedian(ratio)) if np.isfinite(ratio).any() else None,
            "length_ratio_p95": float(np.nanpercentile(ratio, 95)) if np.isfinite(ratio).any() else None,
        }

    pairs = sorted({r["pair"] for r in rows})
    necessary = [r for r in rows if r["planning_necessary"]]
    return {"all": block(rows), "planning_necessary": block(necessary) if necessary else None,
            "per_pair": {p: block([r for r in rows if r["pair"] == p]) for p in pairs}}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--library", type=Path, default=default_library_path())
    ap.add_argument("--per-pair", type=int, default=50, help="queries per ordered sector pair (default 50)")
    ap.add_argument("--seed", type=int, default=1000, help="query seed (worker w uses seed + w; default 1000)")
    ap.add_argument("--reference-samples", type=int, default=2500, help="dimension-RRT samples of the reference")
    ap.add_argument("--no-reference", action="store_true", help="skip the dimension-RRT reference")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--queries-cache", type=Path, help="JSON of the generated queries: read if it exists, else written")
    ap.add_argument("--query-set", metavar="NAME", help="use a stored query set (e.g. planning_necessary) instead of generating")
    ap.add_argument("--generate-only", action="store_true", help="stop after generating (and caching) the queries")
    ap.add_argument("--out", type=Path, default=Path("experiments/library/benchmark"), help="output stem")
    args = ap.parse_args(argv)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))  # unwind, so worker pools shut down
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(name)s: %(message)s")
    from tpee_ompl.model.queries import Query
    from tpee_ompl.model.wearer_arm import default_robot

    t0 = time.perf_counter()
    workers = max(1, args.workers)
    shares = [args.per_pair // workers + (w < args.per_pair % workers) for w in range(workers)]
    ctx = get_context("spawn")
    if args.query_set is not None:
        from tpee_ompl.model.queries import load_queries

        queries = load_queries(args.query_set)
    elif args.queries_cache is not None and args.queries_cache.exists():
        queries = [Query.from_dict(d) for d in json.loads(args.queries_cache.read_text())]
    else:
        with ProcessPoolExecutor(workers, mp_context=ctx) as ex:
            parts = list(ex.map(_gen_queries, [s for s in shares if s], [args.seed + w for w in range(workers) if shares[w]]))
        queries = [Query.from_dict({**d, "id": k}) for k, d in enumerate(d for part in parts for d in part)]
        if args.queries_cache is not None:
            args.queries_cache.write_text(json.dumps([q.to_dict() for q in queries]))
    if args.generate_only:
        return 0
    t_gen = time.perf_counter() - t0
    log.info("%d queries in %.0f s", len(queries), t_gen)

    robot = default_robot()
    lib = PathLibrary.load(args.library, robot, plan=dimension_rrt_planner(robot, max_samples=args.reference_samples))
    queries = [q for q in queries if (q.from_sector, q.to_sector) in lib.pairs]
    # warm-up (imports, caches) on a few queries, not counted
    benchmark_queries(lib, queries[:3])
    lib.reset_stats()
    t1 = time.perf_counter()
    rows = benchmark_queries(lib, queries)
    t_lib = time.perf_counter() - t1
    from tpee_ompl.planning.query_generation import straight_motion_valid

    for row, q in zip(rows, queries, strict=True):
        row["planning_necessary"] = not straight_motion_valid(robot, q.start, q.goal, q.from_sector, q.to_sector)

    t2 = time.perf_counter()
    if not args.no_reference:
        items = [(k, q.start.tolist(), q.goal.tolist(), q.from_sector, q.to_sector) for k, q in enumerate(queries)]
        # small tasks: an interrupted run leaves no worker busy for long (each query's seed is its own)
        chunks = [items[k:k + 10] for k in range(0, len(items), 10)]
        ex = ProcessPoolExecutor(workers, mp_context=ctx)
        try:
            ref = dict(x for part in ex.map(_reference, chunks, [args.reference_samples] * len(chunks), [7] * len(chunks))
                       for x in part)
        finally:  # on Ctrl-C / SIGTERM: drop the queued tasks, let the running ones (<= 10 queries) end
            ex.shutdown(wait=True, cancel_futures=True)
        for k, row in enumerate(rows):
            row["ref_length"] = ref[k]
            row["length_ratio"] = row["length"] / ref[k] if ref[k] > 0 else float("nan")
    t_ref = time.perf_counter() - t2

    summary = _summary(rows)
    summary["library_counters"] = lib.stats()
    summary["parameters"] = {"library": str(args.library), "library_build": lib.build_params, "per_pair": args.per_pair,
                             "seed": args.seed, "workers": workers, "reference_samples": args.reference_samples,
                             "query_stride": lib.query_stride, "n_candidates": lib.n_candidates,
                             "step_rad": robot.max_joint_step()}
    summary["seconds"] = {"query_generation": t_gen, "library_queries": t_lib, "reference": t_ref}
    summary["hardware"] = {"machine": platform.machine(), "processor": platform.processor(), "cpus": os.cpu_count(),
                           "python": platform.python_version()}
    stem = new_output_stem(args.out, (".csv", ".json"))  # never overwrite earlier results
    with open(stem.with_name(stem.name + ".csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    stem.with_name(stem.name + ".json").write_text(json.dumps(summary, indent=1))
    for label in ("all", "planning_necessary"):
        a = summary[label]
        if a is None:
            continue
        print(f"{label}: {a['queries']} queries: query median {a['query_time']['median_ms']:.2f} ms, "
              f"p95 {a['query_time']['p95_ms']:.2f} ms; generation median {a['generation_time']['median_ms']:.3f} ms "
              f"(p95 {a['generation_time']['p95_ms']:.3f}); raw DMP valid {a['raw_dmp_valid_share']:.1%}; "
              f"outcomes {a['outcomes']}; fallback {a['fallback_share']:.1%}; "
              f"length ratio median {a['length_ratio_median']}, p95 {a['length_ratio_p95']}")
    print(f"wrote {stem.with_name(stem.name + '.csv')} and {stem.with_name(stem.name + '.json')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
