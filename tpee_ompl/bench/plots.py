"""Headless PNG plots of a campaign database (matplotlib Agg).

* ``fig15_ratios_<validator>.png``: per-query ratios dimension-RRT / RRT* vs sample count (mean with the
  quartile band, median dashed) with the paper's Table-4 values overlaid, like the paper's Fig. 15.
* ``box_time.png`` / ``box_length.png``: time and raw path length per planner and sample cap.
* ``anytime_cost.png``: median cost of successful runs vs time budget per planner, and the median
  best cost over time from the ``progress`` table.
* ``anytime_within_best.png``: share of queries solved within 5 % of the best path found vs time
  budget per planner (markers); dashed, where the ``progress`` table allows: the same share over
  time inside the longest-budget runs.
"""

from __future__ import annotations

import math
import sqlite3
import warnings
from collections import defaultdict
from pathlib import Path

import numpy as np

from ..files import atomic_path

__all__ = ["make_plots"]


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def make_plots(db_path: str | Path, directory: str | Path, planner: str | None = None,
               reference: str | None = None) -> list[Path]:
    """Write the PNGs into ``directory`` and return their paths (only the plots the data allow).  Matplotlib's
    warnings about the data (a legend with no labelled line when a planner solved nothing, overflow on a log
    axis) are not printed: the plots are drawn from what there is."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        warnings.simplefilter("ignore", RuntimeWarning)
        written = _make_plots(db_path, directory, planner, reference)
    _remove_stale_plots(Path(directory), written)
    return written


_FIG15 = "fig15_ratios_{}.png"
"""Per motion validator: the per-query ratios against the sample count."""
_BOX = {"time": "box_time.png", "solution_length": "box_length.png"}
"""Per run column: its box plot per planner and sample cap."""
_ANYTIME_COST = "anytime_cost.png"
_ANYTIME_WITHIN_BEST = "anytime_within_best.png"
_PLOT_PATTERNS = (_FIG15.format("*"), *_BOX.values(), _ANYTIME_COST, _ANYTIME_WITHIN_BEST)
"""The names :func:`make_plots` writes."""


def _remove_stale_plots(directory: Path, written: list[Path]) -> None:
    """Remove the plots of an earlier build that this one did not draw (a resumed campaign whose data no longer
    allow them), so the folder shows the database it sits beside; other files are left alone."""
    keep = {p.name for p in written}
    for pattern in _PLOT_PATTERNS:
        for p in directory.glob(pattern):
            if p.name not in keep:
                p.unlink(missing_ok=True)


def _make_plots(db_path: str | Path, directory: str | Path, planner: str | None, reference: str | None) -> list[Path]:
    from .report import PAPER_TABLE4, RATIO_METRICS, anytime_table, load_runs, ratio_table, resolve_planner_name

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    plt = _pyplot()
    runs = load_runs(db_path)
    out: list[Path] = []
    it = [r for r in runs if r["comparison"] == "iterations"]
    seen = sorted({r["planner"] for r in it})
    planner = planner or resolve_planner_name("DimensionRRT", seen)
    reference = reference or resolve_planner_name("RRTstar", seen)
    if it and planner != reference and {planner, reference} <= set(seen):  # (as the report's Table 4; one planner at
        # the caps drew an empty "RRTstar / RRTstar")
        ratios = ratio_table(runs, planner, reference)
        for chk in sorted({r["checker"] for r in ratios}):
            fig, ax = plt.subplots(figsize=(7, 4.5))
            has_paper = any(not math.isnan(r["paper"]) for r in ratios)
            for k, key in enumerate(RATIO_METRICS):
                rows = sorted((r for r in ratios if r["checker"] == chk and r["metric"] == key), key=lambda r: r["sample_cap"])
                caps = [r["sample_cap"] for r in rows]
                color = f"C{k}"
                ax.plot(caps, [r["mean"] for r in rows], "o-", color=color, label=f"{rows[0]['label']} (mean)")
                ax.fill_between(caps, [r["q1"] for r in rows], [r["q3"] for r in rows], color=color, alpha=0.15)
                if has_paper:  # the paper's Table 4 is the wearer's
                    pc = sorted(PAPER_TABLE4)
                    ax.plot(pc, [PAPER_TABLE4[c][key] for c in pc], "x:", color=color, alpha=0.8)
            ax.axhline(1.0, color="grey", lw=0.8)
            ax.set_xlabel("samples (dimension-RRT) = iterations (RRT*)")
            ax.set_ylabel(f"{planner} / {reference}")
            paper = "; dotted x: paper Table 4" if has_paper else ""
            ax.set_title(f"Per-query ratios ({chk} motion validator){paper}; band: Q1-Q3")
            ax.title.set_fontsize(9)
            ax.legend(fontsize=7)
            fig.tight_layout()
            p = directory / _FIG15.format(chk)
            _save(fig, p)
            out.append(p)
        for col, label in (("time", "time (s)"), ("solution_length", "raw path length")):
            fname = _BOX[col]
            groups = defaultdict(list)
            for r in it:
                if r["success"]:
                    groups[(int(r["sample_cap"]), r["motion_validator"], r["planner"])].append(float(r[col]))
            if not groups:
                continue
            keys = sorted(groups)
            fig, ax = plt.subplots(figsize=(max(6, 0.8 * len(keys)), 4.5))
            ax.boxplot([groups[k] for k in keys], showfliers=True)
            ax.set_xticks(range(1, len(keys) + 1), [f"{p}\nN={n}\n{c}" for n, c, p in keys], fontsize=7)
            ax.set_ylabel(label)
            if col == "time":
                ax.set_yscale("log")
            ax.set_title(f"Iteration-matched runs: {label} of successful runs")
            fig.tight_layout()
            p = directory / fname
            _save(fig, p)
            out.append(p)
    any_runs = [r for r in runs if r["comparison"] == "anytime"]
    if any_runs:
        fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.5))
        costs = anytime_table(runs)
        for k, pl in enumerate(sorted({r["planner"] for r in any_runs})):
            pts = sorted((r["budget"], r["cost_median"]) for r in costs if r["planner"] == pl)
            ax1.plot([b for b, _ in pts], [c for _, c in pts], "o-", color=f"C{k}", label=pl)
            t, c = _progress_median(db_path, runs, pl)
            if t is not None:
                ax2.step(t, c, where="post", color=f"C{k}", label=pl)
        ax1.set_xscale("log")
        ax1.set_xlabel("time budget (s)")
        ax1.set_ylabel("median raw cost of successful runs")
        ax1.legend(fontsize=7)
        ax2.set_xlabel("time (s)")
        ax2.set_ylabel("median best cost (progress rows)")
        ax2.set_title("longest budget", fontsize=9)
        ax2.legend(fontsize=7)
        fig.tight_layout()
        p = directory / _ANYTIME_COST
        _save(fig, p)
        out.append(p)
        out.append(_within_best_plot(db_path, runs, directory, plt))
    return out


def _within_best_plot(db_path, runs: list[dict], directory: Path, plt) -> Path:
    """``anytime_within_best.png``: the report's within-5 % share per budget and planner (log time axis)."""
    from .report import WITHIN_BEST, anytime_quality_table, best_found

    rows = anytime_quality_table(runs)
    best = best_found(runs)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for k, pl in enumerate(sorted({r["planner"] for r in rows})):
        pts = sorted((r["budget"], r["within_share"]) for r in rows if r["planner"] == pl)
        ax.plot([b for b, _ in pts], [v for _, v in pts], "o-", color=f"C{k}", label=pl)
        t, share = _progress_within(db_path, runs, pl, best, WITHIN_BEST)
        if t is not None:
            ax.plot(t, share, "--", drawstyle="steps-post", color=f"C{k}", lw=1, alpha=0.6)
    ax.set_xscale("log")
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlabel("time budget; dashed: time in the run (s)")
    ax.set_ylabel(f"share of queries within {round((WITHIN_BEST - 1) * 100)} % of the best found")
    ax.set_title("markers: runs of each budget; dashed: progress inside the longest-budget runs", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    p = directory / _ANYTIME_WITHIN_BEST
    _save(fig, p)
    return p


def _longest_budget_runs(runs: list[dict], planner: str | None = None) -> tuple[float, list[dict]]:
    """The longest anytime budget and its runs (of ``planner``, when given)."""
    at = [r for r in runs if r["comparison"] == "anytime"]
    bmax = max(float(r["time_budget"]) for r in at)
    return bmax, [r for r in at if float(r["time_budget"]) == bmax and planner in (None, r["planner"])]


def _progress_series(db_path, run_ids) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """:func:`_series` of the progress rows of ``run_ids`` (empty without any, or without a progress table)."""
    run_ids = list(run_ids)
    con = sqlite3.connect(str(db_path))
    try:
        pcols = {r[1] for r in con.execute("PRAGMA table_info(progress)")}
        if not run_ids or not {"runid", "time", "best_cost"} <= pcols:
            return {}
        marks = ",".join("?" * len(run_ids))
        rows = con.execute(f"SELECT runid, time, best_cost FROM progress WHERE runid IN ({marks}) "
                           "ORDER BY runid, time", run_ids).fetchall()
    finally:
        con.close()
    return _series(rows) if rows else {}


def _progress_within(db_path, runs: list[dict], planner: str, best: dict, within: float):
    """Share of the longest budget's queries whose run's best cost is within ``within`` x best found, over time.

    Only successful runs count (as in the report); a query's share is averaged over its runs. None when
    the planner's runs have no progress rows.
    """
    bmax, at = _longest_budget_runs(runs)
    mine = {r["id"]: r for r in at if r["planner"] == planner}
    series = _progress_series(db_path, mine)
    if not series:
        return None, None
    per_query = defaultdict(int)
    for r in mine.values():
        per_query[r["query_id"]] += 1
    times = [t for ts, cs in series.values() for t, c in zip(ts, cs) if t > 0 and math.isfinite(c)]
    t_end = max([bmax] + [float(ts[-1]) for ts, _ in series.values()])  # runs overshoot their budget a little
    grid = np.geomspace(min(times, default=bmax / 100), t_end, 120)
    share = np.zeros_like(grid)
    for rid, (ts, cs) in series.items():
        r = mine[rid]
        if not r["success"] or r["query_id"] not in best:
            continue
        share += (_cost_at(ts, cs, grid) <= within * best[r["query_id"]]) / per_query[r["query_id"]]
    return grid, share / len({r["query_id"] for r in at})


def _progress_median(db_path, runs: list[dict], planner: str):
    """Median over runs of the best-cost step function, for the longest anytime budget."""
    bmax, mine = _longest_budget_runs(runs, planner)
    series = _progress_series(db_path, (r["id"] for r in mine))
    if not series:
        return None, None
    grid = np.linspace(0, float(bmax), 60)
    med = np.median(np.array([_cost_at(ts, cs, grid) for ts, cs in series.values()]), axis=0)
    med[~np.isfinite(med)] = np.nan
    return grid, med


def _series(rows: list[tuple]) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Per run id, the times and best costs (inf before a first path) of its (runid, time, best_cost)
    progress rows, in the rows' order (time order: the queries sort them)."""
    series: dict[int, list[tuple[float, float]]] = defaultdict(list)
    for rid, t, c in rows:
        if t is not None:
            series[rid].append((float(t), math.inf if c is None else float(c)))
    return {rid: (np.array([t for t, _ in pts]), np.array([c for _, c in pts])) for rid, pts in series.items()}


def _cost_at(ts: np.ndarray, cs: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """A run's best cost at each time of ``grid`` (its step function; inf before its first progress row)."""
    idx = np.searchsorted(ts, grid, side="right") - 1
    return np.where(idx >= 0, cs[np.clip(idx, 0, None)], math.inf)


def _save(fig, path: Path) -> None:
    """Save ``fig`` as PNG at ``path`` atomically (a temporary file, then ``os.replace``), then close it."""
    import matplotlib.pyplot as plt

    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=120, format="png")
    finally:
        plt.close(fig)
