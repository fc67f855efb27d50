"""Campaign report: the paper's Table-4 ratios and honest length figures, as Markdown and CSV.

Everything is read back from the campaign's SQLite database (Planner Arena format, see
:mod:`tpee_ompl.bench.database`).  A run *succeeds* when its status is an exact solution,
OMPL's ``correct_solution`` is 1, the raw path starts at the start and ends at the goal
(``reaches_goal``; OMPL 2.0.1's AORRTC sometimes returns a zero-length path with status "Invalid
goal" that Benchmark marks solved and the database unsolved,
:func:`~tpee_ompl.bench.database.patch_recorded_data`) and every raw-path segment passes ``si.checkMotion``
again (``path_valid_dense``).  Failed and missing runs are counted, never dropped silently: the ratio of
a query is computed only when both planners succeed on it, and ``n`` says how many queries that is.
"""

from __future__ import annotations

import csv
import math
import sqlite3
from collections import defaultdict
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..files import atomic_path, atomic_write_text
from .config import OUR_PLANNER_NOTES, WEARER_PLANNER_NOTES
from .results import planner_name

__all__ = ["OVER_BUDGET", "PAPER_TABLE4", "RATIO_METRICS", "WITHIN_BEST", "anytime_quality_table", "anytime_table",
           "best_found", "length_quality_table", "load_runs", "ratio_table", "resolve_planner_name", "success_table",
           "summarize", "write_report"]

PAPER_TABLE4: dict[int, dict[str, float]] = {
    500: {"time": 0.523, "length": 0.500, "length_dof34": 0.409, "length_dof12": 0.582},
    1000: {"time": 0.492, "length": 0.566, "length_dof34": 0.464, "length_dof12": 0.651},
    1500: {"time": 0.462, "length": 0.636, "length_dof34": 0.531, "length_dof12": 0.714},
    2000: {"time": 0.401, "length": 0.666, "length_dof34": 0.565, "length_dof12": 0.737},
    2500: {"time": 0.377, "length": 0.684, "length_dof34": 0.585, "length_dof12": 0.745},
}
"""Zou et al. 2022, Table 4: dimension-RRT / RRT*, mean of 120 per-query ratios.  The paper's
"second DOF group" is DOF3/DOF4 (``length_dof34``), its "first DOF group" DOF1/DOF2."""

RATIO_METRICS = {
    "time": ("time", "Time"),
    "length": ("solution_length", "4-D path length"),
    "length_dof34": ("length_dof34", "DOF3/DOF4-group length"),
    "length_dof12": ("length_dof12", "DOF1/DOF2-group length"),
}
"""Metric key -> (runs column, label) on the wearer, whose groups are DOF1/DOF2 and DOF3/DOF4."""

GENERIC_LABELS = {"time": "Time", "length": "Path length", "length_dof34": "Other DOFs' length",
                  "length_dof12": "First group's length"}
"""The metrics' labels on a problem without the wearer's sectors (its first group and the rest; no paper figures)."""


def _is_tpee(runs: Sequence[dict]) -> bool:
    """True when the runs are the wearer's cross-sector queries (the paper's Table 4 applies): they have sectors."""
    return any(r.get("from_sector") for r in runs)


def _columns(con: sqlite3.Connection, table: str) -> set[str]:
    return {r[1] for r in con.execute(f"PRAGMA table_info({table})")}


def load_runs(db_path: str | Path) -> list[dict]:
    """One dict per run: planner, experiment parameters and the run's measurements.

    FileNotFoundError for a missing database (sqlite would create an empty one), ValueError naming the file
    when it holds no benchmark runs."""
    if not Path(db_path).is_file():
        raise FileNotFoundError(f"benchmark database not found: {db_path}")
    con = sqlite3.connect(str(db_path))
    try:
        rcols, ecols = _columns(con, "runs"), _columns(con, "experiments")
        want_r = ["id", "time", "solved", "status", "approximate_solution", "correct_solution", "solution_length",
                  "simplified_solution_length", "best_cost", "iterations", "samples", "collision_checks",
                  "length_dof12", "length_dof34", "path_valid_dense", "reaches_goal", "first_solution_time", "planner_error"]
        want_e = ["comparison", "query_set", "query_id", "query_index", "from_sector", "to_sector", "sample_cap",
                  "time_budget", "motion_validator", "straight_length", "timelimit"]
        sel = [f"runs.{c}" if c in rcols else f"NULL AS {c}" for c in want_r]
        sel += [f"experiments.{c}" if c in ecols else f"NULL AS {c}" for c in want_e]
        sql = (f"SELECT plannerConfigs.name AS planner, experiments.name AS experiment, {', '.join(sel)} "
               "FROM runs JOIN experiments ON runs.experimentid = experiments.id "
               "JOIN plannerConfigs ON runs.plannerid = plannerConfigs.id ORDER BY runs.id")
        if not rcols or not ecols:
            raise ValueError(f"{db_path}: not a benchmark database (no runs / experiments tables)")
        cur = con.execute(sql)
        names = [d[0] for d in cur.description]
        rows = [dict(zip(names, r)) for r in cur.fetchall()]
    finally:
        con.close()
    for r in rows:
        r["planner"] = planner_name(r["planner"])
        r["success"] = _success(r)
    return rows


def _hit_max_time(r: dict) -> bool:
    """A run of the sample-capped comparison that stopped at the safety time limit (``max_time``) before its cap:
    not a run at that sample count, so a failure (its path would be compared with runs that drew the whole cap)."""
    it, cap, limit, t = (r.get(k) for k in ("iterations", "sample_cap", "timelimit", "time"))
    if r.get("comparison") != "iterations" or None in (it, cap, limit, t):
        return False
    return int(it) < int(cap) and float(t) >= 0.99 * float(limit)


def _success(r: dict) -> bool:
    return bool(
        not _hit_max_time(r)
        and r["solved"] == 1
        and r["status"] == 6  # exact solution
        and r["reaches_goal"] == 1
        and not r["approximate_solution"]
        and r["correct_solution"] == 1
        and r["path_valid_dense"] == 1
        and r["solution_length"] is not None
        and math.isfinite(float(r["solution_length"]))
    )


def summarize(values: Sequence[float]) -> dict:
    """n, mean, median and quartiles of finite values (NaN when empty)."""
    v = np.asarray([x for x in values if x is not None and math.isfinite(x)], dtype=float)
    if v.size == 0:
        return {"n": 0, "mean": math.nan, "median": math.nan, "q1": math.nan, "q3": math.nan}
    q1, med, q3 = np.percentile(v, [25, 50, 75])
    return {"n": int(v.size), "mean": float(v.mean()), "median": float(med), "q1": float(q1), "q3": float(q3)}


def _per_query_mean(rows: list[dict], col: str) -> dict:
    acc = defaultdict(list)
    for r in rows:
        if r["success"] and r[col] is not None:
            acc[r["query_id"]].append(float(r[col]))
    return {k: float(np.mean(v)) for k, v in acc.items()}


def ratio_table(runs: list[dict], planner: str, reference: str, checker: str | None = None) -> list[dict]:
    """Per sample cap and metric: summary of per-query ratios planner / reference (Table 4).

    Only the iteration comparison; ``checker`` picks the motion validator (default: every one,
    separately, as the ``checker`` field).
    """
    out = []
    it = [r for r in runs if r["comparison"] == "iterations"]
    tpee = _is_tpee(it)
    checkers = sorted({r["motion_validator"] for r in it}) if checker is None else [checker]
    for chk in checkers:
        for cap in sorted({int(r["sample_cap"]) for r in it if r["motion_validator"] == chk}):
            sel = [r for r in it if r["motion_validator"] == chk and int(r["sample_cap"]) == cap]
            a = [r for r in sel if r["planner"] == planner]
            b = [r for r in sel if r["planner"] == reference]
            queries = sorted({r["query_id"] for r in sel}, key=str)
            for key, (col, label) in RATIO_METRICS.items():
                pa, pb = _per_query_mean(a, col), _per_query_mean(b, col)
                ratios = [pa[q] / pb[q] for q in queries if q in pa and q in pb and pb[q] > 0]
                s = summarize(ratios)
                paper = PAPER_TABLE4.get(cap, {}).get(key, math.nan) if tpee else math.nan
                out.append({"checker": chk, "sample_cap": cap, "metric": key, "tpee": tpee,
                            "label": label if tpee else GENERIC_LABELS[key], **s, "queries": len(queries), "paper": paper})
    return out


def success_table(runs: list[dict], expected: dict | None = None) -> list[dict]:
    """Runs and successes per comparison, validator, cap/budget and planner.

    ``expected`` (the campaign's ``campaign.json``) adds the experiments that never finished as
    ``missing`` runs (e.g. after Ctrl-C or a crash).
    """
    groups = defaultdict(list)
    for r in runs:
        key = (r["comparison"], r["motion_validator"], _setting(r), r["planner"])
        groups[key].append(r)
    wanted = _expected_queries(expected) if expected else None
    out = []
    for (comp, chk, setting, planner), rs in sorted(groups.items(), key=lambda kv: tuple(map(str, kv[0]))):
        ids = {r["query_id"] for r in rs}
        row = {"comparison": comp, "checker": chk, "setting": setting, "planner": planner, "runs": len(rs),
               "success": sum(r["success"] for r in rs),
               "invalid_path": sum(1 for r in rs if r["solved"] == 1 and not r["success"] and not _hit_max_time(r)),
               "unsolved": sum(1 for r in rs if r["solved"] != 1 or _hit_max_time(r)),  # max_time: not at the cap
               "cut_by_max_time": sum(1 for r in rs if _hit_max_time(r)),
               "queries": len(ids), "missing_queries": None}
        if wanted is not None:
            row["missing_queries"] = wanted.get((comp, chk, setting), 0) - len(ids)
        out.append(row)
    present = {k[:3] for k in groups}
    for (comp, chk, setting), n in sorted((wanted or {}).items()):
        if (comp, chk, setting) not in present:  # not one run of it finished
            out.append({"comparison": comp, "checker": chk, "setting": setting, "planner": "(every planner)",
                        "runs": 0, "success": 0, "invalid_path": 0, "unsolved": 0, "cut_by_max_time": 0, "queries": 0,
                        "missing_queries": n})
    return out


def _expected_queries(expected: dict) -> dict[tuple[str, str, str], int]:
    """(comparison, validator, cap/budget setting) -> how many queries the campaign (``campaign.json``) runs it on."""
    from .experiment import experiment_specs

    cfg, n = expected["config"], len(expected["queries"])
    out: dict[tuple[str, str, str], int] = defaultdict(int)
    for k in range(n):
        for spec in experiment_specs(cfg, k):
            setting = _setting({"comparison": spec["comparison"], "sample_cap": spec["cap"], "time_budget": spec["budget"]})
            out[(spec["comparison"], spec["checker"], setting)] += 1
    return dict(out)


def _setting(r: dict) -> str:
    """The run's cap or budget as text; "?" where a database not written by this package lacks it."""
    if r["comparison"] == "iterations":
        return f"N={int(r['sample_cap'])}" if r["sample_cap"] is not None else "N=?"
    return f"T={float(r['time_budget']):g}s" if r["time_budget"] is not None else "T=?"


def best_found(runs: list[dict]) -> dict:
    """Query id -> the shortest successful raw path (rad) any planner found for it anywhere in ``runs``."""
    best: dict = {}
    for r in runs:
        if r["success"]:
            q = r["query_id"]
            best[q] = min(best.get(q, math.inf), float(r["solution_length"]))
    return best


def length_quality_table(runs: list[dict]) -> list[dict]:
    """Each planner's raw length relative to the straight start-goal segment and to the best path found.

    ``best`` is the shortest successful raw path any planner found for that query anywhere in the
    campaign.  Per comparison, validator, cap/budget and planner: median and quartiles.
    """
    best = best_found(runs)
    groups = defaultdict(list)
    for r in runs:
        groups[(r["comparison"], r["motion_validator"], _setting(r), r["planner"])].append(r)
    out = []
    for (comp, chk, setting, planner), rs in sorted(groups.items(), key=lambda kv: tuple(map(str, kv[0]))):
        ok = [r for r in rs if r["success"]]
        lb = summarize([float(r["solution_length"]) / float(r["straight_length"]) for r in ok
                        if r["straight_length"] and float(r["straight_length"]) > 0])
        bf = summarize([float(r["solution_length"]) / best[r["query_id"]] for r in ok if best.get(r["query_id"])])
        tm = summarize([float(r["time"]) for r in ok if r["time"] is not None])
        out.append({"comparison": comp, "checker": chk, "setting": setting, "planner": planner,
                    "success": len(ok), "runs": len(rs),
                    "vs_straight_median": lb["median"], "vs_straight_q1": lb["q1"], "vs_straight_q3": lb["q3"],
                    "vs_best_median": bf["median"], "vs_best_q1": bf["q1"], "vs_best_q3": bf["q3"],
                    "time_median": tm["median"]})
    return out


def anytime_table(runs: list[dict]) -> list[dict]:
    """Per budget and planner: successes and the median raw cost (rad) of successful runs."""
    groups = defaultdict(list)
    for r in runs:
        if r["comparison"] == "anytime":
            groups[(float(r["time_budget"]), r["planner"])].append(r)
    out = []
    for (b, planner), rs in sorted(groups.items()):
        s = summarize([float(r["solution_length"]) for r in rs if r["success"]])
        out.append({"budget": b, "planner": planner, "runs": len(rs), "success": s["n"], "cost_median": s["median"],
                    "cost_q1": s["q1"], "cost_q3": s["q3"]})
    return out


OVER_BUDGET = 1.5
"""An anytime run that took more than ``OVER_BUDGET`` x its budget is marked: a planner step that does not poll the
termination condition (OMPL's path simplifier's passes) ran on; its path had more time than the budget's."""

WITHIN_BEST = 1.05
"""A path is *within 5 % of the best found* when its raw length <= ``WITHIN_BEST`` x the best found."""


def anytime_quality_table(runs: list[dict], within: float = WITHIN_BEST) -> list[dict]:
    """Per anytime budget and planner: success, time to the first exact path, length / best found, share within 5 %.

    * ``over_budget``: successful runs whose time exceeds :data:`OVER_BUDGET` x the budget;
    * ``first_time_median``: median over successful runs of ``first_solution_time``; a successful run
      that recorded none (a native planner exposing no cost) contributes its run time, an upper bound
      (it ended with an exact path), counted in ``first_time_from_run_time``; ``first_time_at_run_end``
      counts the other runs whose recorded time is the end of the run (within 1 %: a planner whose
      cost is read only after its run), also upper bounds;
    * ``vs_best_*``: raw length / :func:`best_found` (over the whole campaign) of successful runs;
    * ``within_share``: the mean over the budget's queries (every query of that budget's experiments, any
      planner) of the fraction of this planner's runs on it that succeeded with length <= ``within`` x
      best found; failed and missing runs count as not within.  ``within`` is that sum (with one run per
      query: the number of queries within), ``queries`` the denominator.
    """
    best = best_found(runs)
    anytime = [r for r in runs if r["comparison"] == "anytime"]
    queries: dict[float, set] = defaultdict(set)
    groups: dict[tuple, list] = defaultdict(list)
    for r in anytime:
        b = float(r["time_budget"])
        queries[b].add(r["query_id"])
        groups[(b, r["planner"])].append(r)
    out = []
    for (b, planner), rs in sorted(groups.items()):
        ok = [r for r in rs if r["success"]]
        recorded = [(float(r["first_solution_time"]), float(r["time"])) for r in ok
                    if r["first_solution_time"] is not None and math.isfinite(float(r["first_solution_time"]))]
        fallback = [float(r["time"]) for r in ok
                    if r["first_solution_time"] is None or not math.isfinite(float(r["first_solution_time"]))]
        first = summarize([t for t, _ in recorded] + fallback)
        at_end = sum(1 for t, end in recorded if t >= end - max(0.01 * end, 1e-3))
        bf = summarize([float(r["solution_length"]) / best[r["query_id"]] for r in ok if best.get(r["query_id"])])
        per_query: dict = defaultdict(list)
        for r in rs:
            per_query[r["query_id"]].append(
                bool(r["success"]) and float(r["solution_length"]) <= within * best[r["query_id"]])
        n_within = sum(sum(v) / len(v) for v in per_query.values())
        n_q = len(queries[b])
        over = sum(1 for r in ok if float(r["time"]) > OVER_BUDGET * b)
        out.append({"budget": b, "planner": planner, "runs": len(rs), "success": len(ok), "over_budget": over,
                    "queries": n_q, "first_time_median": first["median"], "first_time_from_run_time": len(fallback),
                    "first_time_at_run_end": at_end,
                    "vs_best_median": bf["median"], "vs_best_q1": bf["q1"], "vs_best_q3": bf["q3"],
                    "within": n_within, "within_share": n_within / n_q if n_q else math.nan})
    return out


def _f(x: float, nd: int = 3) -> str:
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{nd}f}"


def _ratio_markdown(ratios: list[dict], planner: str, reference: str, headline: str | None) -> list[str]:
    """The Table-4 section of the report: per validator and sample cap, the per-query ratios' summaries."""
    lines = [f"## Table 4: {planner} / {reference} at equal sample counts", ""]
    has_paper = any(not math.isnan(r["paper"]) for r in ratios)
    lines.append(f"Mean of per-query ratios{' (paper in brackets)' if has_paper else ''}, then median [Q1, Q3]; "
                 "n = queries where both succeeded (a cell marked n=k had fewer: a reference value of 0, as for a "
                 "query whose start is its goal, gives no ratio). Lengths are raw planner output in the space's "
                 "metric (rad for joint angles).")
    if planner in OUR_PLANNER_NOTES:
        wearer = WEARER_PLANNER_NOTES.get(planner) if any(r.get("tpee") for r in ratios) else None
        lines += ["", f"`{planner}`: {OUR_PLANNER_NOTES[planner]}{'; ' + wearer if wearer else ''}."]
    labels = {r["metric"]: r["label"] for r in ratios}
    checkers = sorted({r["checker"] for r in ratios}, key=lambda c: (c != headline, c))
    for chk in checkers:
        tag = " (headline)" if chk == headline else ""
        lines += ["", f"Motion validator: **{chk}**{tag}", ""]
        lines.append("| N | n | " + " | ".join(labels[k] for k in RATIO_METRICS) + " |")
        lines.append("|---|---|" + "---|" * len(RATIO_METRICS))
        for cap in sorted({r["sample_cap"] for r in ratios if r["checker"] == chk}):
            row = [next(x for x in ratios if x["checker"] == chk and x["sample_cap"] == cap and x["metric"] == key)
                   for key in RATIO_METRICS]
            n = max(r["n"] for r in row)
            cells = []
            for r in row:
                paper = f" ({_f(r['paper'])})" if has_paper else ""
                fewer = f" (n={r['n']})" if r["n"] < n else ""  # a reference value of 0 (start = goal) has no ratio
                cells.append(f"{_f(r['mean'])}{paper} med {_f(r['median'])} [{_f(r['q1'])}, {_f(r['q3'])}]{fewer}")
            lines.append(f"| {cap} | {n}/{row[0]['queries']} | " + " | ".join(cells) + " |")
    return lines + [""]


def _markdown(succ: list[dict], quality: list[dict], anytime: list[dict]) -> str:
    """The report's sections after Table 4: success counts, lengths against the bounds, anytime costs."""
    lines = ["## Success counts", "",
              "| comparison | validator | setting | planner | success / runs | solved but invalid | unsolved | missing queries |",
              "|---|---|---|---|---|---|---|---|"]
    for r in succ:
        miss = "" if r["missing_queries"] is None else str(r["missing_queries"])
        lines.append(f"| {r['comparison']} | {r['checker']} | {r['setting']} | {r['planner']} | {r['success']} / {r['runs']} "
                     f"| {r['invalid_path']} | {r['unsolved']} | {miss} |")
    cut = sum(r["cut_by_max_time"] for r in succ)
    if cut:
        lines += ["", f"{cut} sample-capped run(s) stopped at the time limit (`--max-time`) before their cap: counted as "
                      "unsolved, since their paths came from fewer samples (a longer `--max-time` lets them reach it)."]
    lines += ["", "## Path length relative to the straight start-goal segment (lower bound) and to the best path found",
              "", "| comparison | validator | setting | planner | success | length / straight, median [Q1, Q3] "
              "| length / best found, median [Q1, Q3] | median time (s) |", "|---|---|---|---|---|---|---|---|"]
    for r in quality:
        lines.append(f"| {r['comparison']} | {r['checker']} | {r['setting']} | {r['planner']} | {r['success']}/{r['runs']} "
                     f"| {_f(r['vs_straight_median'])} [{_f(r['vs_straight_q1'])}, {_f(r['vs_straight_q3'])}] "
                     f"| {_f(r['vs_best_median'])} [{_f(r['vs_best_q1'])}, {_f(r['vs_best_q3'])}] | {_f(r['time_median'])} |")
    if anytime:
        lines += ["", "## Anytime comparison: median raw cost (path length in the space's metric) of successful runs", "",
                  "| budget (s) | planner | success / runs | cost median [Q1, Q3] |", "|---|---|---|---|"]
        for r in anytime:
            lines.append(f"| {r['budget']:g} | {r['planner']} | {r['success']}/{r['runs']} "
                         f"| {_f(r['cost_median'])} [{_f(r['cost_q1'])}, {_f(r['cost_q3'])}] |")
    return "\n".join(lines) + "\n"


def _anytime_quality_markdown(rows: list[dict]) -> str:
    """The anytime section on time to the first exact path and length against the best found."""
    if not rows:
        return ""
    pct = round((WITHIN_BEST - 1) * 100)
    lines = ["", "## Anytime comparison: time to the first exact path and length against the best found", "",
             f"Success: successful runs / runs; `k over {OVER_BUDGET:g}x budget`: successful runs that took longer "
             "(a step that does not poll the termination condition, such as a pass of OMPL's path simplifier, ran "
             "on: their paths had more time). First exact path: median over successful runs of the time the "
             "planner first held an exact path (`first_solution_time`: the planner's own for dimension-RRT and the "
             "library and simplifying planners; for native planners the first termination check that saw an exact "
             "solution: a finite best cost, or a path in the problem definition). Marked: `k at run end`, the first "
             "path came as the run ended (RRTConnect stops at its first path); `k from run time`, successful runs "
             "that recorded none (logs of older versions) contribute their run time, an upper bound. "
             "Length / best found: raw length "
             "over the shortest successful path any planner found for that query in the campaign. "
             f"Within {pct} %: queries whose run succeeded with length <= {WITHIN_BEST:g} x best found, over all "
             "queries of that budget (failed or missing runs count as not within).", "",
             "| budget (s) | planner | success / runs | first exact path, median (s) "
             f"| length / best found, median [Q1, Q3] | within {pct} % of best found |",
             "|---|---|---|---|---|---|"]
    for r in rows:
        notes = [f"{r[k]} {label}" for k, label in (("first_time_from_run_time", "from run time"),
                                                      ("first_time_at_run_end", "at run end")) if r[k]]
        fb = f" ({', '.join(notes)})" if notes else ""
        over = f" ({r['over_budget']} over {OVER_BUDGET:g}x budget)" if r.get("over_budget") else ""
        lines.append(f"| {r['budget']:g} | {r['planner']} | {r['success']}/{r['runs']}{over} "
                     f"| {_f(r['first_time_median'])}{fb} "
                     f"| {_f(r['vs_best_median'])} [{_f(r['vs_best_q1'])}, {_f(r['vs_best_q3'])}] "
                     f"| {r['within']:.3g}/{r['queries']} ({_f(r['within_share'], 2)}) |")
    return "\n".join(lines) + "\n"


def _write_csv(path: Path, rows: list[dict]) -> None:
    with atomic_path(path) as tmp, open(tmp, "w", newline="") as f:
        if rows:
            w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
            w.writeheader()
            w.writerows(rows)


def _lost_queries(expected: dict | None) -> str:
    """Markdown list of the queries a campaign could not finish (worker died twice, task raised)."""
    failed = (expected or {}).get("failed_tasks") or []
    if not failed:
        return ""
    lines = ["", "## Lost queries", "",
             "These queries' missing experiments have no rows (nothing is invented for them); "
             "`--resume` runs them again.", "", "| query position | query id | attempts | reason | missing logs |",
             "|---|---|---|---|---|"]
    for f in failed:
        lines.append(f"| {f.get('qpos')} | {f.get('query_id')} | {f.get('attempts')} | {f.get('reason')} "
                     f"| {len(f.get('missing_logs') or [])} |")
    return "\n".join(lines) + "\n"


def write_report(db_path: str | Path, directory: str | Path, expected: dict | None = None,
                 planner: str | None = None, reference: str | None = None) -> dict:
    """Write ``report.md``, ``table4.csv`` (when the campaign ran both planners of the ratio at sample caps), and
    those of ``success.csv``, ``length_quality.csv``, ``anytime.csv``, ``anytime_quality.csv`` that have rows.

    ``planner``/``reference`` default to the campaign's first two iteration planners (or
    DimensionRRT / RRTstar).  Returns the paths, the Markdown text, its ``headline`` (Table 4 and the anytime
    first-path table, what a terminal shows) and the number of runs and successful runs.
    """
    directory = Path(directory)
    runs = load_runs(db_path)
    cfg = (expected or {}).get("config", {})
    names = list(cfg.get("iteration_planners") or ["DimensionRRT", "RRTstar"])
    seen = sorted({r["planner"] for r in runs if r["comparison"] == "iterations"})
    planner = planner or resolve_planner_name(names[0], seen)
    reference = reference or resolve_planner_name(names[1] if len(names) > 1 else "RRTstar", seen)
    headline = (cfg.get("checkers") or ["batched"])[0]
    absent = [p for p in dict.fromkeys((planner, reference)) if p not in seen]
    ratios = ratio_table(runs, planner, reference) if seen and not absent and planner != reference else []
    note = ""
    if seen and not ratios:  # sample caps were run, but not both planners of the ratio
        note = (f"No Table 4: it compares {planner} with {reference} at equal sample counts, and the campaign ran "
                f"{' and '.join(absent)} at no sample cap.\n\n" if absent else "No Table 4: it compares two planners "
                f"at equal sample counts, and the campaign ran only {planner} at its sample caps.\n\n")
    succ = success_table(runs, expected)
    quality = length_quality_table(runs)
    anytime = anytime_table(runs)
    anytime_quality = anytime_quality_table(runs)
    table4 = "\n".join(_ratio_markdown(ratios, planner, reference, headline)) + "\n" if ratios else ""
    rest = _markdown(succ, quality, anytime)
    first = _anytime_quality_markdown(anytime_quality)
    text = note + table4 + rest + first + _lost_queries(expected)
    paths = {"markdown": directory / "report.md"}
    atomic_write_text(paths["markdown"], text)
    if ratios:  # a campaign without sample caps has no Table 4
        paths["csv"] = directory / "table4.csv"
        _write_csv(paths["csv"], ratios)
    for name, rows in (("success", succ), ("length_quality", quality), ("anytime", anytime),
                       ("anytime_quality", anytime_quality)):
        if rows:  # a table the campaign has no runs for (no budgets: no anytime rows) is not written empty
            paths[name] = directory / f"{name}.csv"
            _write_csv(paths[name], rows)
    # what a terminal shows: Table 4 and the first-path / within-5 % table, else why there is no Table 4 or the counts
    summary = "\n\n".join(s.strip("\n") for s in (table4, first) if s) or note.strip("\n") or rest.split("\n\n## ")[0]
    return {**paths, "markdown_text": text, "headline": summary + "\n", "planner": planner, "reference": reference,
            "runs": len(runs), "successes": sum(bool(r["success"]) for r in runs)}


def resolve_planner_name(name: str, seen: Sequence[str]) -> str:
    """Planner names in the DB come from getName(); map a factory key (``module:function``: its function name,
    case, separators and a ``make_`` prefix aside) onto the one DB name equal to it, else the key itself (so a
    report never compares another planner)."""
    if name in seen:
        return name

    def key(text: str) -> str:  # case and separators aside, and a factory's "make_" prefix
        text = text.rsplit(":", 1)[-1].lower()
        return "".join(c for c in text.removeprefix("make_") if c.isalnum())

    same = [s for s in seen if key(s) == key(name)]  # equal, not contained: "rrtstar_k20" is not "RRTstar"
    return same[0] if len(same) == 1 else name
