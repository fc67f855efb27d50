"""Where the barrel can point: posture sectors' pointing ranges and the Monte Carlo pointing workspace.

- :func:`sector_pointing_range`: which barrel directions the pointing system reaches with (DOF1, DOF2)
  at one posture sector's preset (paper Sec. 3.1).
- :func:`sample_pointing_workspace` / :func:`pointing_workspace`: the analogue of the paper's Fig. 4,
  by Monte Carlo sampling of collision-free configurations and the points along the barrel axis
  with a clear line of sight.
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..model.pointing import MAX_TARGET_DISTANCE
from ..model.sectors import SECTORS, posture_preset
from ..validation import MAX_COUNT, check_bool, check_int, check_number
from ._common import Progress, check_view, draw_floor, image_suffixes, output_path, set_view, write_figure
from .meshes import scene_mesh
from .style import DEFAULT_AZIM, DEFAULT_ELEV, SECTOR_COLORS, SILHOUETTE

if TYPE_CHECKING:
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..model.wearer_arm import WearerArm

__all__ = [
    "PointingSamples",
    "fibonacci_sphere",
    "nearest_preset_sector",
    "pointing_workspace",
    "sample_pointing_workspace",
    "sector_pointing_range",
]

log = logging.getLogger(__name__)


def fibonacci_sphere(n: int) -> np.ndarray:
    """Return n nearly uniform unit vectors, shape (n, 3) (Fibonacci lattice)."""
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    phi = i * np.pi * (3.0 - np.sqrt(5.0))
    rho = np.sqrt(1.0 - z * z)
    return np.column_stack([rho * np.cos(phi), rho * np.sin(phi), z])


def nearest_preset_sector(Q: np.ndarray) -> np.ndarray:
    """Posture sector (1-4) whose Table 1 (DOF1, DOF2) preset is nearest to each configuration (N, >= 2) or (>= 2,)."""
    presets = np.array([posture_preset(k) for k in SECTORS])
    Q = np.atleast_2d(np.asarray(Q, dtype=float))
    return np.array(SECTORS)[np.argmin(np.linalg.norm(Q[:, None, :2] - presets[None], axis=2), axis=1)]


def sector_pointing_range(
    robot: WearerArm, sector: int, n_dirs: int = 600, los_range: float = 3.0
) -> tuple[np.ndarray, np.ndarray]:
    """Which barrel directions the pointing system reaches at posture sector ``sector`` (paper Sec. 3.1).

    With (DOF1, DOF2) at the Table 1 preset, a direction u is pointed at by pan = atan2(v_y, v_x),
    tilt = asin(v_z) with v = u in the pan joint's frame (or the mirrored solution pan + pi,
    pi - tilt when the tilt limit allows).  u is *reachable* if one of these configurations is
    within limits, collision-free, and has a clear line of sight ``los_range`` m along the barrel.

    Returns
    -------
    dirs : ndarray, shape (n_dirs, 3)
        Unit vectors, nearly uniform on the sphere.
    reachable : ndarray of bool, shape (n_dirs,)
    """
    n_dirs = check_int("n_dirs", n_dirs, minimum=1, maximum=MAX_COUNT)
    los_range = check_number("los_range (metres)", los_range, low=0.0, low_open=True, high=MAX_RANGE)
    d12 = posture_preset(sector)
    q0 = np.concatenate([d12, np.zeros(robot.nq - 2)])
    R3 = robot.joint_placement(q0, robot.joint_names[2]).rotation
    dirs = fibonacci_sphere(n_dirs)
    v = dirs @ R3  # rows: R3.T @ u
    pan = np.arctan2(v[:, 1], v[:, 0])
    tilt = np.arcsin(np.clip(v[:, 2], -1.0, 1.0))
    reachable = np.zeros(n_dirs, dtype=bool)
    for pan_k, tilt_k in ((pan, tilt), (pan - np.sign(pan) * np.pi, np.sign(tilt) * np.pi - tilt)):
        Q = np.column_stack([np.full(n_dirs, d12[0]), np.full(n_dirs, d12[1]), pan_k, tilt_k])
        todo = ~reachable & robot.are_valid(Q)
        for j in np.flatnonzero(todo):
            p, u = robot.muzzle(Q[j])
            reachable[j] = robot.line_of_sight_clear(Q[j], p + los_range * u)
    return dirs, reachable

MAX_WORKSPACE_SAMPLES = 200_000
"""Most configurations a pointing workspace draws (100,000 took 12 s and 312 MB; 10^7 would take GBs)."""
MAX_RANGE = 0.5 * MAX_TARGET_DISTANCE
"""Metres: the farthest pointing range drawn (its points must stay targets, within ``MAX_TARGET_DISTANCE``)."""
_COST = {"check": 15.0, "sight": 55.0, "plot": 7.0, "draw": 25.0}
"""Microseconds, the progress bar's units (2-core VM, 200,000 samples, 444,000 points: 3, 9, 3 and 8-15 s): one
configuration's collision check, one collision-free configuration's line-of-sight checks, one point's scatter (all
four panels) and its drawing into the file."""
_VALID_SHARE, _CLEAR_SHARE = 0.83, 0.89
"""Of the packaged model's samples, the collision-free share, and of theirs, the share of points with a clear line of
sight per range: the bar's first estimate, corrected once the counts are known."""
_CHUNK = 10_000
"""Configurations checked in one batched call (the bar moves between two)."""

@dataclass(frozen=True)
class PointingSamples:
    """Monte Carlo samples of the pointing workspace (see :func:`sample_pointing_workspace`).

    Attributes
    ----------
    points : ndarray, shape (M, 3), metres
        Points on the barrel axis at ``ranges`` beyond the muzzle, with a clear line of sight.
    range : ndarray, shape (M,), metres
        Distance of each point from the muzzle.
    sector : ndarray, shape (M,), int
        Posture sector (1-4) whose (DOF1, DOF2) preset is nearest to the sample's.
    n_samples, n_valid : int
        Configurations drawn, and how many were collision-free.
    """

    points: np.ndarray
    range: np.ndarray
    sector: np.ndarray
    n_samples: int
    n_valid: int


def sample_pointing_workspace(
    robot: WearerArm,
    n_samples: int,
    rng: np.random.Generator,
    ranges: Sequence[float] = (0.25, 0.5, 1.0),
    presets_only: bool = False,
    *,
    progress: bool = False,
) -> PointingSamples:
    """Monte Carlo pointing workspace: where the barrel can point from collision-free configurations.

    The paper (Sec. 2, Fig. 4) adds a translational DOF along the barrel and samples the
    resulting 5-DOF workspace.  Here: draw ``n_samples`` configurations uniformly within the joint
    limits (or, with ``presets_only``, pan/tilt only at the four Table 1 (DOF1, DOF2) presets),
    keep the collision-free ones (batched :meth:`WearerArm.are_valid` calls of 10,000), and for each
    keep the points ``p + r u`` (muzzle p, barrel axis u, r in ``ranges``) whose segment from the
    muzzle is clear of the wearer and boom.

    Parameters
    ----------
    robot : WearerArm
    n_samples : int, >= 1
    rng : numpy.random.Generator
    ranges : sequence of float, metres, > 0
    presets_only : bool
    progress : bool
        A progress bar on stderr with the time left, shown when the sampling takes more than 2 s.

    Returns
    -------
    PointingSamples
    """
    rs = _check_sampling(n_samples, rng, ranges)
    per_sample = _COST["check"] + _VALID_SHARE * _COST["sight"]
    with Progress("workspace", n_samples * per_sample, check_bool("progress", progress)) as bar:
        return _sample(robot, n_samples, rng, rs, presets_only, bar, 0.0)


def _check_sampling(n_samples: int, rng: np.random.Generator, ranges: Sequence[float]) -> np.ndarray:
    """The sampling arguments checked (ValueError naming the bad one); the ranges sorted, metres."""
    check_int("n_samples", n_samples, minimum=1, maximum=MAX_WORKSPACE_SAMPLES)
    if not isinstance(rng, np.random.Generator):
        raise ValueError(f"rng must be a numpy.random.Generator (np.random.default_rng(seed)), got {type(rng).__name__}")
    try:
        rs = np.sort(np.atleast_1d(np.asarray(ranges, dtype=float)))
    except (TypeError, ValueError):
        raise ValueError(f"ranges must be distances in metres, got {ranges!r}") from None
    if rs.ndim != 1 or len(rs) == 0 or not np.all((rs > 0) & (rs <= MAX_RANGE)):
        raise ValueError(f"ranges must be distances in (0, {MAX_RANGE:g}] metres, got {ranges!r}")
    return rs


def _sample(robot: WearerArm, n_samples: int, rng: np.random.Generator, rs: np.ndarray, presets_only: bool,
            bar: Progress, per_point: float) -> PointingSamples:
    """:func:`sample_pointing_workspace` with checked arguments, counting its work on ``bar`` (``per_point``: the
    units each point will cost the caller afterwards, in the bar's estimate of what is left)."""
    n_samples = int(n_samples)
    Q = rng.uniform(robot.lower, robot.upper, size=(n_samples, robot.nq))
    if presets_only:
        presets = np.array([posture_preset(k) for k in SECTORS])
        Q[:, :2] = presets[rng.integers(0, len(SECTORS), n_samples)]
    valid = np.empty(n_samples, dtype=bool)
    for a in range(0, n_samples, _CHUNK):  # batched calls, so the bar moves
        valid[a:a + _CHUNK] = robot.are_valid(Q[a:a + _CHUNK])
        bar.add(_COST["check"] * len(valid[a:a + _CHUNK]), "collision checks")
    Q = Q[valid]
    bar.expect(len(Q) * (_COST["sight"] + _CLEAR_SHARE * len(rs) * per_point))
    sect = nearest_preset_sector(Q)
    pts, rr, ss = [], [], []
    counted = 0
    for n, (q, k) in enumerate(zip(Q, sect), start=1):
        p, u = robot.muzzle(q)
        # a shorter segment is a prefix of a longer one: if the longest is clear, all are
        if robot.line_of_sight_clear(q, p + rs[-1] * u):
            ok = rs
        else:
            ok = [r for r in rs[:-1] if robot.line_of_sight_clear(q, p + r * u)]
        for r in ok:
            pts.append(p + r * u)
            rr.append(r)
            ss.append(k)
        if n % 1000 == 0 or n == len(Q):
            bar.add(_COST["sight"] * (n - counted), "lines of sight")
            counted = n
    bar.expect(len(pts) * per_point)
    return PointingSamples(np.array(pts).reshape(-1, 3), np.array(rr), np.array(ss, dtype=int), n_samples, len(Q))


def pointing_workspace(
    robot: WearerArm,
    n_samples: int,
    rng: np.random.Generator,
    out_path: str | os.PathLike | None = None,
    *,
    ranges: Sequence[float] = (0.25, 0.5, 1.0),
    color_by: str = "sector",
    presets_only: bool = False,
    dpi: int = 110,
    force: bool = True,
    progress: bool = False,
) -> Figure:
    """Draw the analogue of the paper's Fig. 4: a 3D view and three projections of the pointing workspace.

    Samples with :func:`sample_pointing_workspace`, then scatters the points coloured by posture
    sector (``color_by="sector"``) or by range from the muzzle (``color_by="range"``), over a faint
    wearer.  Saved to ``out_path`` if given (``force=False``: an existing file is refused).  ``progress``: a
    progress bar on stderr with the time left (sampling, plotting, drawing into the file), shown when the whole takes
    more than 2 s (``tpee-ompl workspace`` shows it unless ``--no-progress``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    with Progress("workspace", 0.0, check_bool("progress", progress)) as bar:
        return _pointing_workspace(robot, n_samples, rng, out_path, ranges, color_by, presets_only, dpi, force, bar)


def _progress_tick(ax: Axes, bar: Progress, units: float, phase: str) -> Artist:
    """An invisible artist drawn after everything else in ``ax``: it adds ``units`` to ``bar`` when the panel has been
    drawn into the file (a figure of 400,000 points takes 8-15 s to save: the bar moves panel by panel)."""
    from matplotlib.artist import Artist

    class _Tick(Artist):
        def draw(self, renderer: object) -> None:
            bar.add(units, phase)

    tick = _Tick()
    tick.set_zorder(1e9)
    tick.set_in_layout(False)
    ax.add_artist(tick)
    return tick


def _pointing_workspace(robot: WearerArm, n_samples: int, rng: np.random.Generator,
                        out_path: str | os.PathLike | None, ranges: Sequence[float], color_by: str, presets_only: bool,
                        dpi: int, force: bool, bar: Progress) -> Figure:
    """:func:`pointing_workspace`, its work counted on ``bar``."""
    from matplotlib.collections import PolyCollection
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    if color_by not in ("sector", "range"):
        raise ValueError(f"color_by must be 'sector' or 'range', got {color_by!r}")
    check_view(DEFAULT_ELEV, DEFAULT_AZIM, dpi)
    out = None if out_path is None else output_path(out_path, image_suffixes(), force)  # before sampling and drawing
    rs = _check_sampling(n_samples, rng, ranges)
    t0 = time.perf_counter()
    per_point = _COST["plot"] + (_COST["draw"] if out is not None else 0.0)
    bar.expect(n_samples * (_COST["check"] + _VALID_SHARE * (_COST["sight"] + _CLEAR_SHARE * len(rs) * per_point)))
    s = _sample(robot, n_samples, rng, rs, presets_only, bar, per_point)
    if s.n_valid == 0:  # (only the figure's title said "0 of N configurations collision-free")
        log.warning("none of the %d configurations drawn is collision-free: the figure shows no points (is every "
                    "state in collision? check the model's obstacles and margins)", s.n_samples)
    mesh = scene_mesh(robot)
    lo, hi = mesh.view_box(list(s.points), 10.0)
    if color_by == "sector":
        colors = [SECTOR_COLORS[k] for k in s.sector]
    else:
        from matplotlib import colormaps

        span = max(float(np.ptp(s.range)), 1e-9) if len(s.range) else 1.0
        colors = colormaps["viridis"]((s.range - (s.range.min() if len(s.range) else 0.0)) / span)

    fig = Figure(figsize=(12.0, 9.0), dpi=dpi)
    grid = fig.add_gridspec(3, 2, width_ratios=(2.0, 1.0))
    ax3 = fig.add_subplot(grid[:, 0], projection="3d")
    draw_floor(ax3, lo, hi)
    ax3.add_collection3d(Poly3DCollection(mesh.wearer_polys, facecolors=mesh.wearer_colors, edgecolors="none"))
    if len(s.points):
        ax3.scatter(*s.points.T, s=1.5, c=colors, alpha=0.5, depthshade=False)
    quarter = len(s.points) / 4  # each panel plots and draws every point
    bar.add(_COST["plot"] * quarter, "plotting")
    set_view(ax3, lo, hi, DEFAULT_ELEV, DEFAULT_AZIM)
    views = ((0, 1, "top view (x, y)"), (0, 2, "side view (x, z)"), (1, 2, "back view (y, z)"))
    for n, (a, b, name) in enumerate(views):
        ax = fig.add_subplot(grid[n, 1])
        if len(s.points):
            ax.scatter(s.points[:, a], s.points[:, b], s=1.0, c=colors, alpha=0.35, linewidths=0)
        bar.add(_COST["plot"] * quarter)
        # wearer silhouette: projected faces, drawn on top so it reads as the obstacle
        silhouette = PolyCollection(mesh.wearer_polys[:, :, [a, b]], facecolors=SILHOUETTE, edgecolors="none")
        ax.add_collection(silhouette)
        ax.set_xlim(lo[a], hi[a])
        ax.set_ylim(lo[b], hi[b])
        ax.set_aspect("equal")
        ax.set_xlabel("xyz"[a] + " (m)")
        ax.set_ylabel("xyz"[b] + " (m)")
        ax.set_title(name, fontsize=9)
        if a == 1:
            ax.invert_xaxis()  # seen from behind, the wearer's left (+y) is on the left
    if color_by == "sector":
        from matplotlib.lines import Line2D

        handles = [
            Line2D([], [], ls="", marker="o", color=c, label=f"posture sector {k}") for k, c in SECTOR_COLORS.items()
        ]
    else:
        from matplotlib import colormaps
        from matplotlib.lines import Line2D

        rs = np.unique(s.range) if len(s.range) else np.asarray(ranges)
        norm = (rs - rs.min()) / max(float(np.ptp(rs)), 1e-9)
        handles = [
            Line2D([], [], ls="", marker="o", color=colormaps["viridis"](v), label=f"{r:.2f} m")
            for r, v in zip(rs, norm)
        ]
    ax3.legend(handles=handles, loc="upper left", fontsize=8)
    fig.suptitle(
        f"Pointing workspace (Monte Carlo): {s.n_valid} of {s.n_samples} configurations collision-free;\n"
        f"{len(s.points)} points on the barrel axis {', '.join(f'{r:g}' for r in np.sort(ranges))} m beyond the muzzle "
        "with a clear line of sight",
        fontsize=10,
    )
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    fig.set_layout_engine(None)  # laid out: else savefig draws every point once more, with drawing disabled, first
    if out is not None:
        ticks = [_progress_tick(ax, bar, _COST["draw"] * quarter, "drawing") for ax in fig.axes] if bar.enabled else []
        try:
            write_figure(fig, out, dpi, force)
        finally:
            for tick in ticks:
                tick.remove()
    log.info(
        "pointing_workspace: %d samples, %d valid, %d points, %.2f s",
        s.n_samples,
        s.n_valid,
        len(s.points),
        time.perf_counter() - t0,
    )
    return fig
