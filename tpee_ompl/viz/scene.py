"""Still pictures: the wearer, the arm, the line of sight, the posture sectors.

- :func:`render_scene` / :func:`save_scene`: the wearer, the arm at q, the line of sight from the
  muzzle to a target (dashed green if clear, red if blocked), optionally the four posture
  sectors' pointing ranges and a path's muzzle trace.
- :func:`render_sectors`: the four posture sectors side by side with their pointing ranges.

Everything draws with matplotlib's 3D axes on headless Figures (no pyplot, no display needed).
"""

from __future__ import annotations

import logging
import os
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..model.sectors import SECTORS, posture_preset
from ..validation import MAX_JOINT_VALUE, check_bool, check_number, check_type
from ._common import (check_target_off_muzzle, check_view, check_waypoints, clip_segment, draw_floor, image_suffixes,
                      new_axes, optional_target, output_path, set_view, write_figure)
from .animation import muzzle_trace, resample_path
from .meshes import arm_polygons, scene_mesh
from .style import DEFAULT_AZIM, DEFAULT_ELEV, LOS_BLOCKED, LOS_CLEAR, SECTOR_COLORS, hex_rgb
from .workspace import nearest_preset_sector, sector_pointing_range

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..model.wearer_arm import WearerArm

__all__ = ["FAN_CENTRE", "FAN_RADIUS", "render_scene", "render_sectors", "save_scene"]

log = logging.getLogger(__name__)

FAN_CENTRE = np.array([0.0, 0.0, 1.3])
"""Metres: centre of the sphere on which pointing directions are drawn (the chest)."""
FAN_RADIUS = 1.15
"""Metres: radius of that sphere."""


def draw_pointing_range(ax: Axes, dirs: np.ndarray, reachable: np.ndarray, color: str, label: str) -> None:
    """Draw unit pointing directions ``dirs`` (m, 3) on the chest sphere (:data:`FAN_CENTRE`, :data:`FAN_RADIUS`):
    the ``reachable`` ones as dots in ``color``, the others (blind) as grey crosses."""
    pts = FAN_CENTRE + FAN_RADIUS * dirs
    ax.scatter(*pts[reachable].T, s=4, color=color, alpha=0.6, depthshade=False, label=label)
    if (~reachable).any():
        ax.scatter(
            *pts[~reachable].T, s=6, marker="x", color="0.3", alpha=0.7, linewidths=0.7, depthshade=False, label="blind"
        )


# ---------------------------------------------------------------------------- scene
def render_scene(
    robot: WearerArm,
    q: Any,
    target: Any = None,
    sectors: bool = False,
    ax: Axes | None = None,
    path: Any = None,
    *,
    elev: float = DEFAULT_ELEV,
    azim: float = DEFAULT_AZIM,
    title: str | None = None,
    max_extent: float = 3.0,
) -> Figure:
    """Draw the wearer, the arm at q, and optionally the line of sight, the sectors and a path.

    Parameters
    ----------
    robot : WearerArm
    q : array_like, shape (4,), radians
        (DOF1, DOF2, pan, tilt).  Drawn red if invalid (outside limits or colliding); beyond the
        +/-``MAX_JOINT_VALUE`` rad any joint takes (as a ``path``): ValueError.
    target : array_like, shape (3,), metres, optional
        Drawn as a star; the segment muzzle -> target is dashed green if the line of sight is
        clear (:meth:`WearerArm.line_of_sight_clear`), red if blocked.  A target at the muzzle has no
        direction: ValueError.  A target further than
        ``max_extent`` m from the scene centre is not zoomed to: the line is clipped at the view box.
    sectors : bool
        Overlay the four posture sectors (paper Table 1, Fig. 8): a ghost of the boom at each
        preset, labelled S1-S4 at its pointing-system position (coloured by :data:`SECTOR_COLORS`),
        and the pointing range of the sector whose preset is nearest to q's (DOF1, DOF2)
        (:func:`sector_pointing_range`): reachable barrel directions as dots on a 1.15 m sphere
        around the chest, blind directions as grey crosses.  See :func:`render_sectors` for all four.
    ax : 3D Axes, optional
        Axes to draw into (a new headless Figure otherwise).
    path : array_like, shape (K, 4), radians, optional
        A joint-space path; its muzzle trace is drawn (dotted, with start/end markers).
    elev, azim : float, degrees
        Camera.
    title : str, optional
        Default: q in degrees, validity, line-of-sight state.
    max_extent : float, metres
        Positive: how far from the scene centre a target or path point may be and still be zoomed to.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    from ..model.wearer_arm import WearerArm

    t0 = time.perf_counter()
    check_view(elev, azim)
    q = check_type("robot", robot, WearerArm).check_config(q)
    if np.abs(q).max() > MAX_JOINT_VALUE:  # as a path's (check_waypoints): 1e300 drew a 2901-px title
        raise ValueError(f"q holds {np.abs(q).max():g}, beyond the +/-{MAX_JOINT_VALUE:g} rad any joint takes")
    sectors = check_bool("sectors", sectors)
    max_extent = check_number("max_extent (metres)", max_extent, low=0.0, low_open=True)
    tgt = optional_target(target)
    W = check_waypoints(robot, path) if path is not None else None
    check_target_off_muzzle(robot, q, tgt)
    if ax is None:
        ax = new_axes()
    mesh = scene_mesh(robot)
    valid = robot.is_valid(q)
    arm_p, arm_c = arm_polygons(robot, q, mesh, valid)
    polys, colors = [mesh.wearer_polys, arm_p], [mesh.wearer_colors, arm_c]

    extra: list[np.ndarray] = []
    fan: tuple[np.ndarray, np.ndarray] | None = None
    fan_sector = 0
    if sectors:
        for k in SECTORS:
            qk = np.concatenate([posture_preset(k), q[2:]])
            if np.allclose(qk[:2], q[:2]):
                continue
            gp, gc = arm_polygons(robot, qk, mesh, True, boom_only=True, rgba=(*hex_rgb(SECTOR_COLORS[k]), 0.35))
            polys.append(gp)
            colors.append(gc)
        fan_sector = int(nearest_preset_sector(q)[0])
        fan = sector_pointing_range(robot, fan_sector)
        extra += [FAN_CENTRE - FAN_RADIUS, FAN_CENTRE + FAN_RADIUS]
    muzzle_p, muzzle_u = robot.muzzle(q)
    if tgt is not None:
        extra.append(tgt)
    trace = muzzle_trace(robot, resample_path(W, 60)) if W is not None else None
    if trace is not None:
        extra += list(trace)
    lo, hi = mesh.view_box(extra, max_extent)

    draw_floor(ax, lo, hi)
    coll = Poly3DCollection(np.concatenate(polys), facecolors=np.concatenate(colors), edgecolors="none", linewidths=0)
    ax.add_collection3d(coll)
    # aim ray: where the barrel points (thin grey), independent of the target
    tip = clip_segment(muzzle_p, muzzle_p + 2.0 * muzzle_u, lo, hi)
    ax.plot(*np.stack([muzzle_p, tip]).T, color="0.35", lw=0.8, ls=":", zorder=5)
    ax.scatter(*muzzle_p, color="k", s=12, zorder=6)
    los_state = ""
    if tgt is not None:
        clear = robot.line_of_sight_clear(q, tgt)
        end = clip_segment(muzzle_p, tgt, lo, hi)
        ax.plot(*np.stack([muzzle_p, end]).T, color=LOS_CLEAR if clear else LOS_BLOCKED, lw=2.0, ls="--", zorder=7)
        inside = np.allclose(end, tgt)
        if inside:
            ax.scatter(*tgt, marker="*", s=160, color="#facc15", edgecolors="k", zorder=8)
        else:
            ax.text(*end, f" target ({tgt[0]:.1f}, {tgt[1]:.1f}, {tgt[2]:.1f}) m", fontsize=7)
        cosang = float(np.dot(muzzle_u, (tgt - muzzle_p) / max(np.linalg.norm(tgt - muzzle_p), 1e-12)))
        err = np.degrees(np.arccos(np.clip(cosang, -1.0, 1.0)))
        los_state = f" | LOS {'clear' if clear else 'BLOCKED'}, aim error {err:.1f}°"
    if fan is not None:
        draw_pointing_range(ax, *fan, SECTOR_COLORS[fan_sector], f"reachable from sector {fan_sector}")
        for k in SECTORS:  # the four pointing-system positions (paper Fig. 8)
            pk = robot.joint_placement(np.concatenate([posture_preset(k), q[2:]]), robot.joint_names[2]).translation
            ax.text(*pk, f" S{k}", color=SECTOR_COLORS[k], fontsize=9, fontweight="bold")
        ax.legend(loc="upper left", fontsize=7, markerscale=3, title="barrel directions", title_fontsize=7)
    if trace is not None:
        ax.plot(*trace.T, color="#db2777", lw=1.6, zorder=6)
        ax.scatter(*trace[0], color="#db2777", marker="o", s=25, zorder=6)
        ax.scatter(*trace[-1], color="#db2777", marker="s", s=25, zorder=6)
    set_view(ax, lo, hi, elev, azim)
    if title is None:
        qd = ", ".join(f"{v:.0f}" for v in np.degrees(q))
        title = f"q = ({qd})°  {'valid' if valid else 'INVALID'}{los_state}"
    ax.set_title(title, fontsize=9, color="k" if valid else LOS_BLOCKED)
    log.debug("render_scene: %d faces in %.3f s", len(coll.get_paths()), time.perf_counter() - t0)
    return ax.figure


def render_sectors(
    robot: WearerArm,
    out_path: str | os.PathLike | None = None,
    *,
    n_dirs: int = 500,
    elev: float = DEFAULT_ELEV,
    azim: float = DEFAULT_AZIM,
    dpi: int = 100,
    force: bool = True,
) -> Figure:
    """Draw the four posture sectors side by side: each preset's arm and its pointing range (paper Figs. 8-9).

    Each panel shows the arm at the Table 1 (DOF1, DOF2) preset and the barrel directions it can
    reach there (:func:`sector_pointing_range`) as dots on a sphere around the chest, blind
    directions as grey crosses.  Saved to ``out_path`` if given (``force=False``: an existing file is refused).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    from ..model.wearer_arm import WearerArm

    check_view(elev, azim, dpi)
    check_type("robot", robot, WearerArm)
    out = None if out_path is None else output_path(out_path, image_suffixes(), force)  # before the drawing
    mesh = scene_mesh(robot)
    fig = Figure(figsize=(11.0, 10.0), dpi=dpi)
    lo, hi = mesh.view_box([FAN_CENTRE - FAN_RADIUS, FAN_CENTRE + FAN_RADIUS], 10.0)
    for n, k in enumerate(SECTORS, start=1):
        ax = fig.add_subplot(2, 2, n, projection="3d")
        dirs, ok = sector_pointing_range(robot, k, n_dirs=n_dirs)
        q = np.concatenate([posture_preset(k), np.zeros(robot.nq - 2)])
        ap, ac = arm_polygons(robot, q, mesh, robot.is_valid(q))
        draw_floor(ax, lo, hi)
        ax.add_collection3d(
            Poly3DCollection(
                np.concatenate([mesh.wearer_polys, ap]),
                facecolors=np.concatenate([mesh.wearer_colors, ac]),
                edgecolors="none",
            )
        )
        draw_pointing_range(ax, dirs, ok, SECTOR_COLORS[k], "reachable")
        set_view(ax, lo, hi, elev, azim)
        deg = np.degrees(posture_preset(k))
        ax.set_title(
            f"posture sector {k}: DOF1 {deg[0]:.0f}°, DOF2 {deg[1]:.0f}°; {ok.mean():.0%} of directions reachable",
            fontsize=9,
        )
        ax.legend(loc="upper left", fontsize=7, markerscale=2)
    fig.tight_layout()
    if out is not None:
        write_figure(fig, out, dpi, force)
    return fig


def save_scene(
    robot: WearerArm,
    q: Any,
    out_path: str | os.PathLike,
    target: Any = None,
    sectors: bool = False,
    path: Any = None,
    *,
    dpi: int = 110,
    force: bool = True,
    **kwargs: Any,
) -> Path:
    """Render :func:`render_scene` to an image file (format from the suffix: .png, .pdf, .svg, ...).

    Returns the written path (``force=False``: an existing file is refused).  Extra keyword arguments go to
    :func:`render_scene`.
    """
    out = output_path(out_path, image_suffixes(), force)
    check_view(kwargs.get("elev", DEFAULT_ELEV), kwargs.get("azim", DEFAULT_AZIM), dpi)
    fig = render_scene(robot, q, target=target, sectors=sectors, path=path, **kwargs)
    return write_figure(fig, out, dpi, force, bbox_inches="tight")
