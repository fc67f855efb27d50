"""Headless pictures of the wearer and the arm: scenes, path animations, the pointing workspace.

Everything draws with matplotlib's 3D axes and needs no display (use the ``Agg`` backend).
The wearer's collision primitives (boxes, spheres, capsules) and the arm are turned into one
triangle/quad soup and drawn as a single ``Poly3DCollection``, so matplotlib depth-sorts every
face against every other face (separate artists would only be sorted as wholes).

Public functions
----------------
- :func:`render_scene` / :func:`save_scene`: the wearer, the arm at q, the line of sight from the
  muzzle to a target (dashed green if clear, red if blocked), optionally the four posture
  sectors' pointing ranges and a path's muzzle trace.
- :func:`animate_path`: a GIF (Pillow) or MP4 (ffmpeg, if installed) of a joint-space path,
  resampled to a bounded number of frames, with the muzzle trace.
- :func:`pointing_workspace`: the analogue of the paper's Fig. 4, by Monte Carlo sampling of
  collision-free configurations and the points along the barrel axis with a clear line of sight.
- :func:`view_meshcat`: an interactive view with Pinocchio's ``MeshcatVisualizer`` (optional extra).
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import coal
import numpy as np
import pinocchio as pin

from ..model.sectors import SECTORS, posture_preset

if TYPE_CHECKING:  # matplotlib is imported lazily so that importing the package stays cheap
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..model.wearer_arm import WearerArm

__all__ = [
    "SECTOR_COLORS",
    "PointingSamples",
    "ViewerUnavailableError",
    "animate_path",
    "pointing_workspace",
    "render_scene",
    "render_sectors",
    "sector_pointing_range",
    "resample_path",
    "sample_pointing_workspace",
    "save_scene",
    "view_meshcat",
]

log = logging.getLogger(__name__)

SECTOR_COLORS = {1: "#1f77b4", 2: "#ff7f0e", 3: "#2ca02c", 4: "#9467bd"}
"""Posture sector -> matplotlib colour, shared by every figure."""

DEFAULT_ELEV = 18.0
"""Degrees: default camera elevation."""
DEFAULT_AZIM = -125.0
"""Degrees: default camera azimuth (from behind the wearer's right shoulder, so the arm on the back shows)."""

_ARM_COLOR = np.array([0.10, 0.35, 0.80])
_BARREL_COLOR = np.array([0.05, 0.15, 0.45])
_INVALID_COLOR = np.array([0.90, 0.08, 0.08])
_LOS_CLEAR = "#16a34a"
_LOS_BLOCKED = "#dc2626"
_SILHOUETTE = (0.2, 0.2, 0.2, 0.08)
_LIGHT = np.array([-0.35, -0.55, 0.76]) / np.linalg.norm([-0.35, -0.55, 0.76])
_WEARER_COLORS = {  # by link-name prefix; geometry names are "<link>_<i>"
    "helmet": (0.33, 0.37, 0.22),
    "head": (0.87, 0.70, 0.56),
    "neck": (0.87, 0.70, 0.56),
    "hand": (0.87, 0.70, 0.56),
    "backpack": (0.45, 0.33, 0.20),
    "plate": (0.40, 0.45, 0.28),
    "rifle": (0.18, 0.18, 0.18),
    "mount": (0.30, 0.30, 0.30),
    "foot": (0.20, 0.17, 0.13),
}
_WEARER_DEFAULT = (0.62, 0.60, 0.45)


class ViewerUnavailableError(ImportError):
    """The optional interactive viewer (meshcat) is not installed."""


# ---------------------------------------------------------------------------- primitives -> polygons
def _revolve(profile_r: np.ndarray, profile_z: np.ndarray, n_theta: int) -> np.ndarray:
    """Quads (M, 4, 3) of the surface of revolution of a (r, z) profile about the local z axis."""
    th = np.linspace(0.0, 2.0 * np.pi, n_theta + 1)
    c, s = np.cos(th), np.sin(th)
    grid = np.stack(
        [
            profile_r[:, None] * c[None, :],
            profile_r[:, None] * s[None, :],
            np.broadcast_to(profile_z[:, None], (len(profile_z), n_theta + 1)),
        ],
        axis=-1,
    )  # (rings, n_theta+1, 3)
    quads = np.stack([grid[:-1, :-1], grid[:-1, 1:], grid[1:, 1:], grid[1:, :-1]], axis=2)
    return quads.reshape(-1, 4, 3)


def _sphere_quads(radius: float, n_theta: int, n_phi: int) -> np.ndarray:
    phi = np.linspace(-np.pi / 2, np.pi / 2, n_phi + 1)
    return _revolve(radius * np.cos(phi), radius * np.sin(phi), n_theta)


def _capsule_quads(radius: float, half_length: float, n_theta: int, n_cap: int) -> np.ndarray:
    phi = np.linspace(-np.pi / 2, 0.0, n_cap + 1)
    r = np.concatenate([radius * np.cos(phi), radius * np.cos(phi[::-1])])
    z = np.concatenate([radius * np.sin(phi) - half_length, half_length - radius * np.sin(phi[::-1])])
    return _revolve(r, z, n_theta)


_BOX_FACES = np.array([[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]])


def _box_quads(half: np.ndarray) -> np.ndarray:
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float) * half
    return corners[_BOX_FACES]


def primitive_polygons(geom: coal.CollisionGeometry, placement: pin.SE3, resolution: int = 14) -> np.ndarray:
    """Faces of one collision primitive in the world frame.

    Parameters
    ----------
    geom : coal.Box, coal.Sphere, coal.Capsule or coal.Cylinder
        Capsules and cylinders are along their local z (Coal convention).
    placement : pin.SE3
        World placement of the geometry.
    resolution : int
        Facets around a circle.

    Returns
    -------
    ndarray, shape (M, 4, 3), metres
    """
    n_cap = max(2, resolution // 4)
    if isinstance(geom, coal.Box):
        local = _box_quads(np.asarray(geom.halfSide, dtype=float))
    elif isinstance(geom, coal.Sphere):
        local = _sphere_quads(float(geom.radius), resolution, max(4, resolution // 2))
    elif isinstance(geom, coal.Capsule):
        local = _capsule_quads(float(geom.radius), float(geom.halfLength), resolution, n_cap)
    elif isinstance(geom, coal.Cylinder):
        r, h = float(geom.radius), float(geom.halfLength)
        local = _revolve(np.array([0.0, r, r, 0.0]), np.array([-h, -h, h, h]), resolution)
    else:
        raise ValueError(f"cannot draw geometry of type {type(geom).__name__}")
    R, t = np.asarray(placement.rotation), np.asarray(placement.translation)
    return local @ R.T + t


def _shade(polys: np.ndarray, rgb: np.ndarray, alpha: float = 1.0) -> np.ndarray:
    """Per-face RGBA (M, 4): a Lambert-like shade of rgb, two-sided so face winding does not matter."""
    n = np.cross(polys[:, 2] - polys[:, 0], polys[:, 3] - polys[:, 1])
    norm = np.linalg.norm(n, axis=1)
    norm[norm < 1e-12] = 1.0
    k = 0.40 + 0.60 * np.abs(n @ _LIGHT) / norm
    rgba = np.empty((len(polys), 4))
    rgba[:, :3] = np.clip(np.asarray(rgb)[None, :] * k[:, None], 0.0, 1.0)
    rgba[:, 3] = alpha
    return rgba


def _wearer_color(name: str) -> tuple[float, float, float]:
    for prefix, rgb in _WEARER_COLORS.items():
        if name.startswith(prefix):
            return rgb
    return _WEARER_DEFAULT


@dataclass
class _SceneMesh:
    """Static wearer faces (computed once per robot) plus the arm's geometry ids."""

    wearer_polys: np.ndarray
    wearer_colors: np.ndarray
    arm_ids: list[int]
    barrel_ids: set[int]
    lo: np.ndarray
    hi: np.ndarray


_MESH_CACHE: dict[int, _SceneMesh] = {}


def _scene_mesh(robot: WearerArm) -> _SceneMesh:
    key = id(robot)
    if key in _MESH_CACHE:
        return _MESH_CACHE[key]
    polys, colors, arm_ids, barrel_ids = [], [], [], set()
    barrel_joint = robot.model.getJointId(robot.joint_names[-1])
    for i, go in enumerate(robot.gmodel.geometryObjects):
        if go.parentJoint == 0:
            p = primitive_polygons(go.geometry, go.placement)
            polys.append(p)
            colors.append(_shade(p, np.array(_wearer_color(go.name))))
        else:
            arm_ids.append(i)
            if go.parentJoint == barrel_joint:
                barrel_ids.add(i)
    wp = np.concatenate(polys)
    # view box: the wearer plus a sphere of the arm's reach around joint 1
    pin.forwardKinematics(robot.model, robot.data, pin.neutral(robot.model))
    pivot = robot.data.oMi[1].translation.copy()
    reach = float(robot.lever_arms()[0])
    pts = wp.reshape(-1, 3)
    lo = np.minimum(pts.min(axis=0), pivot - reach)
    hi = np.maximum(pts.max(axis=0), pivot + reach)
    lo[2] = max(lo[2], 0.0)
    mesh = _SceneMesh(wp, np.concatenate(colors), arm_ids, barrel_ids, lo, hi)
    _MESH_CACHE[key] = mesh
    return mesh


def _arm_polygons(
    robot: WearerArm, q: np.ndarray, mesh: _SceneMesh, valid: bool, boom_only: bool = False, rgba: Any = None
) -> tuple[np.ndarray, np.ndarray]:
    """Arm faces (M, 4, 3) and colours (M, 4) at q: red when invalid, ``rgba`` (a ghost) if given."""
    pin.forwardKinematics(robot.model, robot.data, q)
    pin.updateGeometryPlacements(robot.model, robot.data, robot.gmodel, robot.gdata)
    polys, colors = [], []
    for i in mesh.arm_ids:
        if boom_only and i in mesh.barrel_ids:
            continue
        go = robot.gmodel.geometryObjects[i]
        p = primitive_polygons(go.geometry, robot.gdata.oMg[i].copy())
        if rgba is not None:
            c = _shade(p, np.asarray(rgba[:3]), alpha=rgba[3])
        else:
            c = _shade(p, _INVALID_COLOR if not valid else (_BARREL_COLOR if i in mesh.barrel_ids else _ARM_COLOR))
        polys.append(p)
        colors.append(c)
    return np.concatenate(polys), np.concatenate(colors)


# ---------------------------------------------------------------------------- axes helpers
def _new_axes(figsize: tuple[float, float] = (7.0, 7.0), dpi: int = 110) -> Axes:
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, dpi=dpi)  # not pyplot: no global state, no display needed
    return fig.add_subplot(projection="3d")


def _set_view(ax: Axes, lo: np.ndarray, hi: np.ndarray, elev: float, azim: float) -> None:
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(tuple(hi - lo))  # equal metres per unit on all three axes
    ax.view_init(elev=elev, azim=azim)
    ax.set_xlabel("x (m, forward)")
    ax.set_ylabel("y (m, left)")
    ax.set_zlabel("z (m)")
    ax.tick_params(labelsize=7)


def _floor(ax: Axes, lo: np.ndarray, hi: np.ndarray) -> None:
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    z = lo[2]
    quad = [[(lo[0], lo[1], z), (hi[0], lo[1], z), (hi[0], hi[1], z), (lo[0], hi[1], z)]]
    ax.add_collection3d(Poly3DCollection(quad, facecolors=(0.85, 0.85, 0.85, 0.35), edgecolors="none"))


def _view_box(mesh: _SceneMesh, extra: Sequence[np.ndarray], max_extent: float) -> tuple[np.ndarray, np.ndarray]:
    """Box around the wearer and arm, grown to include extra points within ``max_extent`` of its centre."""
    lo, hi = mesh.lo.copy(), mesh.hi.copy()
    centre = (lo + hi) / 2
    for p in extra:
        if p is not None and np.linalg.norm(np.asarray(p) - centre) <= max_extent:
            lo, hi = np.minimum(lo, p), np.maximum(hi, p)
    pad = 0.05 * (hi - lo)
    lo, hi = lo - pad, hi + pad
    lo[2] = max(lo[2], 0.0)
    return lo, hi


def _clip_segment(a: np.ndarray, b: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """End point of segment a->b clipped to the box [lo, hi] (a is inside)."""
    d = b - a
    t = 1.0
    for k in range(3):
        if d[k] > 1e-12:
            t = min(t, (hi[k] - a[k]) / d[k])
        elif d[k] < -1e-12:
            t = min(t, (lo[k] - a[k]) / d[k])
    return a + max(t, 0.0) * d


def _check_target(target: Any) -> np.ndarray | None:
    if target is None:
        return None
    t = np.asarray(target, dtype=float)
    if t.shape != (3,) or not np.all(np.isfinite(t)):
        raise ValueError(f"target must be 3 finite numbers (x, y, z in metres), got {target!r}")
    return t


def _check_waypoints(robot: WearerArm, waypoints: Any) -> np.ndarray:
    W = np.asarray(waypoints, dtype=float)
    if W.ndim != 2 or W.shape[1] != robot.nq or len(W) < 1:
        raise ValueError(f"waypoints must have shape (K, {robot.nq}) with K >= 1; got {W.shape}")
    if not np.all(np.isfinite(W)):
        raise ValueError("waypoints contain NaN or inf")
    return W


def resample_path(waypoints: np.ndarray, n: int) -> np.ndarray:
    """Resample a piecewise-linear joint-space path to n points evenly spaced in arc length.

    Parameters
    ----------
    waypoints : ndarray, shape (K, d), radians
    n : int, >= 1

    Returns
    -------
    ndarray, shape (n, d); the first and last rows are the path's start and end.
    """
    W = np.asarray(waypoints, dtype=float)
    if W.ndim != 2 or len(W) < 1:
        raise ValueError(f"waypoints must have shape (K, d) with K >= 1; got {W.shape}")
    if n < 1:
        raise ValueError(f"n must be >= 1, got {n}")
    if len(W) == 1 or n == 1:
        return np.repeat(W[:1], n, axis=0)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(W, axis=0), axis=1))])
    if s[-1] < 1e-12:
        return np.repeat(W[:1], n, axis=0)
    u = np.linspace(0.0, s[-1], n)
    return np.stack([np.interp(u, s, W[:, k]) for k in range(W.shape[1])], axis=1)


def _muzzle_trace(robot: WearerArm, Q: np.ndarray) -> np.ndarray:
    return np.array([robot.muzzle(q)[0] for q in Q])


# ---------------------------------------------------------------------------- sectors overlay
_FAN_CENTRE = np.array([0.0, 0.0, 1.3])
"""Metres: centre of the sphere on which pointing directions are drawn (the chest)."""
_FAN_RADIUS = 1.15


def _fibonacci_sphere(n: int) -> np.ndarray:
    """Return n nearly uniform unit vectors, shape (n, 3) (Fibonacci lattice)."""
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    phi = i * np.pi * (3.0 - np.sqrt(5.0))
    rho = np.sqrt(1.0 - z * z)
    return np.column_stack([rho * np.cos(phi), rho * np.sin(phi), z])


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
    d12 = posture_preset(sector)
    q0 = np.concatenate([d12, np.zeros(robot.nq - 2)])
    R3 = robot.joint_placement(q0, robot.joint_names[2]).rotation
    dirs = _fibonacci_sphere(n_dirs)
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


def _nearest_sector(q: np.ndarray) -> int:
    presets = np.array([posture_preset(k) for k in SECTORS])
    return int(SECTORS[int(np.argmin(np.linalg.norm(presets - np.asarray(q)[:2], axis=1)))])


def _draw_pointing_range(ax: Axes, dirs: np.ndarray, reachable: np.ndarray, color: str, label: str) -> None:
    pts = _FAN_CENTRE + _FAN_RADIUS * dirs
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
        (DOF1, DOF2, pan, tilt).  Drawn red if invalid (outside limits or colliding).
    target : array_like, shape (3,), metres, optional
        Drawn as a star; the segment muzzle -> target is dashed green if the line of sight is
        clear (:meth:`WearerArm.line_of_sight_clear`), red if blocked.  A target further than
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

    Returns
    -------
    matplotlib.figure.Figure
    """
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    t0 = time.perf_counter()
    q = robot.check_config(q)
    tgt = _check_target(target)
    W = _check_waypoints(robot, path) if path is not None else None
    if ax is None:
        ax = _new_axes()
    mesh = _scene_mesh(robot)
    valid = robot.is_valid(q)
    arm_p, arm_c = _arm_polygons(robot, q, mesh, valid)
    polys, colors = [mesh.wearer_polys, arm_p], [mesh.wearer_colors, arm_c]

    extra: list[np.ndarray] = []
    fan: tuple[np.ndarray, np.ndarray] | None = None
    fan_sector = 0
    if sectors:
        for k in SECTORS:
            qk = np.concatenate([posture_preset(k), q[2:]])
            if np.allclose(qk[:2], q[:2]):
                continue
            gp, gc = _arm_polygons(robot, qk, mesh, True, boom_only=True, rgba=(*_hex_rgb(SECTOR_COLORS[k]), 0.35))
            polys.append(gp)
            colors.append(gc)
        fan_sector = _nearest_sector(q)
        fan = sector_pointing_range(robot, fan_sector)
        extra += [_FAN_CENTRE - _FAN_RADIUS, _FAN_CENTRE + _FAN_RADIUS]
    muzzle_p, muzzle_u = robot.muzzle(q)
    if tgt is not None:
        extra.append(tgt)
    trace = _muzzle_trace(robot, resample_path(W, 60)) if W is not None else None
    if trace is not None:
        extra += list(trace)
    lo, hi = _view_box(mesh, extra, max_extent)

    _floor(ax, lo, hi)
    coll = Poly3DCollection(np.concatenate(polys), facecolors=np.concatenate(colors), edgecolors="none", linewidths=0)
    ax.add_collection3d(coll)
    # aim ray: where the barrel points (thin grey), independent of the target
    tip = _clip_segment(muzzle_p, muzzle_p + 2.0 * muzzle_u, lo, hi)
    ax.plot(*np.stack([muzzle_p, tip]).T, color="0.35", lw=0.8, ls=":", zorder=5)
    ax.scatter(*muzzle_p, color="k", s=12, zorder=6)
    los_state = ""
    if tgt is not None:
        clear = robot.line_of_sight_clear(q, tgt)
        end = _clip_segment(muzzle_p, tgt, lo, hi)
        ax.plot(*np.stack([muzzle_p, end]).T, color=_LOS_CLEAR if clear else _LOS_BLOCKED, lw=2.0, ls="--", zorder=7)
        inside = np.allclose(end, tgt)
        if inside:
            ax.scatter(*tgt, marker="*", s=160, color="#facc15", edgecolors="k", zorder=8)
        else:
            ax.text(*end, f" target ({tgt[0]:.1f}, {tgt[1]:.1f}, {tgt[2]:.1f}) m", fontsize=7)
        cosang = float(np.dot(muzzle_u, (tgt - muzzle_p) / max(np.linalg.norm(tgt - muzzle_p), 1e-12)))
        err = np.degrees(np.arccos(np.clip(cosang, -1.0, 1.0)))
        los_state = f" | LOS {'clear' if clear else 'BLOCKED'}, aim error {err:.1f}°"
    if fan is not None:
        _draw_pointing_range(ax, *fan, SECTOR_COLORS[fan_sector], f"reachable from sector {fan_sector}")
        for k in SECTORS:  # the four pointing-system positions (paper Fig. 8)
            pk = robot.joint_placement(np.concatenate([posture_preset(k), q[2:]]), robot.joint_names[2]).translation
            ax.text(*pk, f" S{k}", color=SECTOR_COLORS[k], fontsize=9, fontweight="bold")
        ax.legend(loc="upper left", fontsize=7, markerscale=3, title="barrel directions", title_fontsize=7)
    if trace is not None:
        ax.plot(*trace.T, color="#db2777", lw=1.6, zorder=6)
        ax.scatter(*trace[0], color="#db2777", marker="o", s=25, zorder=6)
        ax.scatter(*trace[-1], color="#db2777", marker="s", s=25, zorder=6)
    _set_view(ax, lo, hi, elev, azim)
    if title is None:
        qd = ", ".join(f"{v:.0f}" for v in np.degrees(q))
        title = f"q = ({qd})°  {'valid' if valid else 'INVALID'}{los_state}"
    ax.set_title(title, fontsize=9, color="k" if valid else _LOS_BLOCKED)
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
) -> Figure:
    """Draw the four posture sectors side by side: each preset's arm and its pointing range (paper Figs. 8-9).

    Each panel shows the arm at the Table 1 (DOF1, DOF2) preset and the barrel directions it can
    reach there (:func:`sector_pointing_range`) as dots on a sphere around the chest, blind
    directions as grey crosses.  Saved to ``out_path`` if given.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    mesh = _scene_mesh(robot)
    fig = Figure(figsize=(11.0, 10.0), dpi=dpi)
    lo, hi = _view_box(mesh, [_FAN_CENTRE - _FAN_RADIUS, _FAN_CENTRE + _FAN_RADIUS], 10.0)
    for n, k in enumerate(SECTORS, start=1):
        ax = fig.add_subplot(2, 2, n, projection="3d")
        dirs, ok = sector_pointing_range(robot, k, n_dirs=n_dirs)
        q = np.concatenate([posture_preset(k), np.zeros(robot.nq - 2)])
        ap, ac = _arm_polygons(robot, q, mesh, robot.is_valid(q))
        _floor(ax, lo, hi)
        ax.add_collection3d(
            Poly3DCollection(
                np.concatenate([mesh.wearer_polys, ap]),
                facecolors=np.concatenate([mesh.wearer_colors, ac]),
                edgecolors="none",
            )
        )
        _draw_pointing_range(ax, dirs, ok, SECTOR_COLORS[k], "reachable")
        _set_view(ax, lo, hi, elev, azim)
        deg = np.degrees(posture_preset(k))
        ax.set_title(
            f"posture sector {k}: DOF1 {deg[0]:.0f}°, DOF2 {deg[1]:.0f}°; {ok.mean():.0%} of directions reachable",
            fontsize=9,
        )
        ax.legend(loc="upper left", fontsize=7, markerscale=2)
    fig.tight_layout()
    if out_path is not None:
        out = Path(out_path)
        out.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(out, dpi=dpi)
        log.info("wrote %s", out)
    return fig


def _hex_rgb(color: str) -> tuple[float, float, float]:
    from matplotlib.colors import to_rgb

    return to_rgb(color)


def save_scene(
    robot: WearerArm,
    q: Any,
    out_path: str | os.PathLike,
    target: Any = None,
    sectors: bool = False,
    path: Any = None,
    *,
    dpi: int = 110,
    **kwargs: Any,
) -> Path:
    """Render :func:`render_scene` to an image file (format from the suffix: .png, .pdf, .svg, ...).

    Returns the written path.  Extra keyword arguments go to :func:`render_scene`.
    """
    out = Path(out_path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig = render_scene(robot, q, target=target, sectors=sectors, path=path, **kwargs)
    fig.savefig(out, dpi=dpi, bbox_inches="tight")
    log.info("wrote %s", out)
    return out


# ---------------------------------------------------------------------------- animation
def animate_path(
    robot: WearerArm,
    waypoints: Any,
    out_path: str | os.PathLike,
    target_a: Any = None,
    target_b: Any = None,
    fps: int = 10,
    frames: int = 40,
    *,
    elev: float = DEFAULT_ELEV,
    azim: float = DEFAULT_AZIM,
    dpi: int = 80,
    title: str | None = None,
) -> Path:
    """Animate a joint-space path (e.g. a cross-sector motion) with the muzzle trace.

    Parameters
    ----------
    robot : WearerArm
    waypoints : array_like, shape (K, 4), radians
        Any planner's or the DMP library's path; resampled to ``frames`` configurations evenly
        spaced in joint-space arc length (:func:`resample_path`), so the file size is bounded.
    out_path : path
        ``.gif`` (Pillow, always available) or ``.mp4`` (needs ffmpeg on PATH).
    target_a, target_b : array_like, shape (3,), metres, optional
        The start and goal targets.  The line of sight is drawn to ``target_a`` during the first half
        of the motion and to ``target_b`` during the second (green clear / red blocked).
    fps : int
        Frames per second.
    frames : int, >= 2
        Number of frames.
    elev, azim : float, degrees
    dpi : int
    title : str, optional

    Returns
    -------
    Path of the written file.  Frames whose configuration is invalid show the arm in red.
    """
    from matplotlib import animation
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    t0 = time.perf_counter()
    W = _check_waypoints(robot, waypoints)
    if frames < 2:
        raise ValueError(f"frames must be >= 2, got {frames}")
    if fps < 1:
        raise ValueError(f"fps must be >= 1, got {fps}")
    out = Path(out_path)
    suffix = out.suffix.lower()
    if suffix == ".gif":
        writer: Any = animation.PillowWriter(fps=fps)
    elif suffix == ".mp4":
        if not animation.writers.is_available("ffmpeg"):
            raise RuntimeError("writing .mp4 needs ffmpeg on PATH; write a .gif instead (Pillow)")
        writer = animation.FFMpegWriter(fps=fps)
    else:
        raise ValueError(f"unsupported animation format {out.suffix!r}: use .gif or .mp4")
    ta, tb = _check_target(target_a), _check_target(target_b)
    Q = resample_path(W, frames)
    valid = robot.are_valid(Q)
    muzzles = [robot.muzzle(q) for q in Q]
    trace = np.array([m[0] for m in muzzles])
    targets = [ta if (i < frames / 2 or tb is None) else tb for i in range(frames)]
    targets = [t if t is not None else (ta if ta is not None else tb) for t in targets]
    clear = [robot.line_of_sight_clear(q, t) if t is not None else True for q, t in zip(Q, targets)]
    mesh = _scene_mesh(robot)
    arm = [_arm_polygons(robot, q, mesh, bool(v)) for q, v in zip(Q, valid)]
    lo, hi = _view_box(mesh, [*trace, *(t for t in (ta, tb) if t is not None)], 3.0)

    ax = _new_axes(figsize=(6.0, 6.0), dpi=dpi)
    fig = ax.figure
    _floor(ax, lo, hi)
    coll = Poly3DCollection(
        np.concatenate([mesh.wearer_polys, arm[0][0]]),
        facecolors=np.concatenate([mesh.wearer_colors, arm[0][1]]),
        edgecolors="none",
        linewidths=0,
    )
    ax.add_collection3d(coll)
    for t, lab in ((ta, "A"), (tb, "B")):
        if t is not None and np.all(t >= lo) and np.all(t <= hi):
            ax.scatter(*t, marker="*", s=140, color="#facc15", edgecolors="k")
            ax.text(*t, f" {lab}", fontsize=8)
    ax.plot(*trace.T, color="0.6", lw=0.8, ls=":")  # the whole trace, faint
    (done,) = ax.plot([], [], [], color="#db2777", lw=2.0)
    (los,) = ax.plot([], [], [], lw=1.8, ls="--")
    _set_view(ax, lo, hi, elev, azim)
    head = title or "cross-sector motion"
    txt = ax.set_title("", fontsize=9)

    def draw(i: int) -> None:
        coll.set_verts(np.concatenate([mesh.wearer_polys, arm[i][0]]))
        coll.set_facecolor(np.concatenate([mesh.wearer_colors, arm[i][1]]))
        done.set_data_3d(*trace[: i + 1].T)
        if targets[i] is not None:
            end = _clip_segment(trace[i], targets[i], lo, hi)
            los.set_data_3d(*np.stack([trace[i], end]).T)
            los.set_color(_LOS_CLEAR if clear[i] else _LOS_BLOCKED)
        state = "valid" if valid[i] else "INVALID"
        txt.set_text(f"{head}  frame {i + 1}/{frames}  {state}")
        txt.set_color("k" if valid[i] else _LOS_BLOCKED)

    out.parent.mkdir(parents=True, exist_ok=True)
    with writer.saving(fig, str(out), dpi):
        for i in range(frames):
            draw(i)
            writer.grab_frame()
    n_bad = int((~valid).sum())
    if n_bad:
        log.warning("animate_path: %d of %d frames are invalid (drawn red)", n_bad, frames)
    log.info("wrote %s (%d frames) in %.1f s", out, frames, time.perf_counter() - t0)
    return out


# ---------------------------------------------------------------------------- pointing workspace (Fig. 4)
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
) -> PointingSamples:
    """Monte Carlo pointing workspace: where the barrel can point from collision-free configurations.

    The paper (Sec. 2, Fig. 4) adds a translational DOF along the barrel and samples the
    resulting 5-DOF workspace.  Here: draw ``n_samples`` configurations uniformly within the joint
    limits (or, with ``presets_only``, pan/tilt only at the four Table 1 (DOF1, DOF2) presets),
    keep the collision-free ones (one batched :meth:`WearerArm.are_valid` call), and for each
    keep the points ``p + r u`` (muzzle p, barrel axis u, r in ``ranges``) whose segment from the
    muzzle is clear of the wearer and boom.

    Parameters
    ----------
    robot : WearerArm
    n_samples : int, >= 1
    rng : numpy.random.Generator
    ranges : sequence of float, metres, > 0
    presets_only : bool

    Returns
    -------
    PointingSamples
    """
    if n_samples < 1:
        raise ValueError(f"n_samples must be >= 1, got {n_samples}")
    rs = np.sort(np.asarray(ranges, dtype=float))
    if rs.ndim != 1 or len(rs) == 0 or not np.all(rs > 0):
        raise ValueError(f"ranges must be positive distances in metres, got {ranges!r}")
    Q = rng.uniform(robot.lower, robot.upper, size=(n_samples, robot.nq))
    presets = np.array([posture_preset(k) for k in SECTORS])
    if presets_only:
        Q[:, :2] = presets[rng.integers(0, len(SECTORS), n_samples)]
    Q = Q[robot.are_valid(Q)]
    sect = np.array(SECTORS)[np.argmin(np.linalg.norm(Q[:, None, :2] - presets[None], axis=2), axis=1)]
    pts, rr, ss = [], [], []
    for q, k in zip(Q, sect):
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
) -> Figure:
    """Draw the analogue of the paper's Fig. 4: a 3D view and three projections of the pointing workspace.

    Samples with :func:`sample_pointing_workspace`, then scatters the points coloured by posture
    sector (``color_by="sector"``) or by range from the muzzle (``color_by="range"``), over a faint
    wearer.  Saved to ``out_path`` if given.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.collections import PolyCollection
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    if color_by not in ("sector", "range"):
        raise ValueError(f"color_by must be 'sector' or 'range', got {color_by!r}")
    t0 = time.perf_counter()
    s = sample_pointing_workspace(robot, n_samples, rng, ranges=ranges, presets_only=presets_only)
    mesh = _scene_mesh(robot)
    lo, hi = _view_box(mesh, list(s.points), 10.0)
    if color_by == "sector":
        colors = [SECTOR_COLORS[k] for k in s.sector]
    else:
        from matplotlib import colormaps

        span = max(float(np.ptp(s.range)), 1e-9) if len(s.range) else 1.0
        colors = colormaps["viridis"]((s.range - (s.range.min() if len(s.range) else 0.0)) / span)

    fig = Figure(figsize=(12.0, 9.0), dpi=dpi)
    grid = fig.add_gridspec(3, 2, width_ratios=(2.0, 1.0))
    ax3 = fig.add_subplot(grid[:, 0], projection="3d")
    _floor(ax3, lo, hi)
    ax3.add_collection3d(Poly3DCollection(mesh.wearer_polys, facecolors=mesh.wearer_colors, edgecolors="none"))
    if len(s.points):
        ax3.scatter(*s.points.T, s=1.5, c=colors, alpha=0.5, depthshade=False)
    _set_view(ax3, lo, hi, DEFAULT_ELEV, DEFAULT_AZIM)
    views = ((0, 1, "top view (x, y)"), (0, 2, "side view (x, z)"), (1, 2, "back view (y, z)"))
    for n, (a, b, name) in enumerate(views):
        ax = fig.add_subplot(grid[n, 1])
        if len(s.points):
            ax.scatter(s.points[:, a], s.points[:, b], s=1.0, c=colors, alpha=0.35, linewidths=0)
        # wearer silhouette: projected faces, drawn on top so it reads as the obstacle
        silhouette = PolyCollection(mesh.wearer_polys[:, :, [a, b]], facecolors=_SILHOUETTE, edgecolors="none")
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
    if out_path is not None:
        out = Path(out_path)
        out.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(out, dpi=dpi)
        log.info("wrote %s", out)
    log.info(
        "pointing_workspace: %d samples, %d valid, %d points, %.2f s",
        s.n_samples,
        s.n_valid,
        len(s.points),
        time.perf_counter() - t0,
    )
    return fig


# ---------------------------------------------------------------------------- meshcat
def view_meshcat(robot: WearerArm, q: Any = None, *, open_browser: bool = False, zmq_url: str | None = None) -> Any:
    """Show the wearer and the arm at q in Pinocchio's ``MeshcatVisualizer`` (optional extra).

    Parameters
    ----------
    robot : WearerArm
    q : array_like, shape (4,), radians, optional
        Default: the neutral configuration.
    open_browser : bool
        Open the viewer's URL in a browser.
    zmq_url : str, optional
        Connect to a running ``meshcat-server`` instead of starting one.

    Returns
    -------
    pinocchio.visualize.MeshcatVisualizer
        Call ``.display(q)`` on it to move the arm.

    Raises
    ------
    ViewerUnavailableError
        (an ``ImportError``) if meshcat is not installed: ``pip install meshcat`` or
        ``pip install 'tpee_ompl[viewer]'``.
    """
    try:
        import meshcat  # noqa: F401
    except ImportError as exc:
        raise ViewerUnavailableError(
            "the interactive viewer needs meshcat: pip install meshcat (or pip install 'tpee_ompl[viewer]')"
        ) from exc
    from pinocchio.visualize import MeshcatVisualizer

    q = pin.neutral(robot.model) if q is None else robot.check_config(q)
    vmodel = robot.gmodel.copy()
    for go in vmodel.geometryObjects:
        rgb = _wearer_color(go.name) if go.parentJoint == 0 else tuple(_ARM_COLOR)
        go.meshColor = np.array([*rgb, 1.0])
    viz = MeshcatVisualizer(robot.model, robot.gmodel, vmodel)
    viz.initViewer(open=open_browser, zmq_url=zmq_url, loadModel=True)
    viz.display(q)
    log.info("meshcat viewer at %s", viz.viewer.url())
    return viz
