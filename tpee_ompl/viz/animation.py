"""Animations of joint-space paths: the arm moving, the muzzle trace growing, the line of sight.

- :func:`animate_path`: a GIF (Pillow) or MP4 (ffmpeg, if installed) of a joint-space path,
  resampled to a bounded number of frames, with the muzzle trace.
- :func:`resample_path`: a piecewise-linear path at n points evenly spaced in arc length.
"""

from __future__ import annotations

import logging
import os
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..files import atomic_path
from ..validation import MAX_COUNT, MAX_JOINT_VALUE, as_float_array, check_bool, check_int
from ._common import (Progress, check_view, check_waypoints, clip_segment, draw_floor,
                      new_axes, optional_target, output_path, set_view)
from .meshes import arm_polygons, scene_mesh
from .style import DEFAULT_AZIM, DEFAULT_ELEV, LOS_BLOCKED, LOS_CLEAR

if TYPE_CHECKING:
    from ..model.wearer_arm import WearerArm

__all__ = ["MAX_FRAMES", "animate_path", "muzzle_trace", "resample_path"]

log = logging.getLogger(__name__)


MAX_FRAMES = 500
"""Most frames an animation takes (every frame is kept in memory until the file is written: 200 frames took
17 s and 390 MB)."""
MAX_ANIMATION_DPI = 200
"""Highest resolution of an animation's frames (dots per inch; a frame at 2000 took 576 MB)."""
MAX_FRAME_DPI2 = MAX_FRAMES * 80**2
"""Most ``frames * dpi**2`` an animation may ask for (the memory grows with both: 150 frames at dpi 200 took 1.2
GB): 500 frames at the default dpi 80, 80 at dpi 200."""
_DRAW_UNITS, _ENCODE_UNITS = 5, 2
"""A frame's share of the progress bar while it is drawn and while the GIF is encoded (58 and 23 ms at dpi 80: 500
frames took 29 s to draw and 11 s to encode); an MP4 is encoded by ffmpeg while the frames are drawn."""


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
    W = as_float_array(waypoints, "waypoints")
    if W.ndim != 2 or len(W) < 1:
        raise ValueError(f"waypoints must have shape (K, d) with K >= 1; got {W.shape}")
    if not np.all(np.isfinite(W)) or np.abs(W).max() > MAX_JOINT_VALUE:  # NaN rows, or an overflowing arc length
        raise ValueError(f"waypoints must be finite joint values within +/-{MAX_JOINT_VALUE:g}")
    n = check_int("n (points)", n, minimum=1, maximum=MAX_COUNT)
    if len(W) == 1 or n == 1:
        return np.repeat(W[:1], n, axis=0)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(W, axis=0), axis=1))])
    if s[-1] < 1e-12:
        return np.repeat(W[:1], n, axis=0)
    u = np.linspace(0.0, s[-1], n)
    return np.stack([np.interp(u, s, W[:, k]) for k in range(W.shape[1])], axis=1)


def muzzle_trace(robot: WearerArm, Q: np.ndarray) -> np.ndarray:
    """Muzzle positions (N, 3), metres, of the configurations Q (N, nq)."""
    return np.array([robot.muzzle(q)[0] for q in Q])


def _abandon(writer: Any) -> None:
    """Stop a movie writer whose frames will not be used: no GIF encoded from the frames so far (Pillow's ``finish``
    took 7 s after a Ctrl-C at frame 300, and raised IndexError, hiding the Ctrl-C, before the first frame); an
    ffmpeg process is ended."""
    proc = getattr(writer, "_proc", None)  # matplotlib's MovieWriter (ffmpeg); PillowWriter holds frames only
    if proc is not None and proc.poll() is None:
        proc.kill()
        proc.communicate()


def _finish(writer: Any, bar: Progress, units: int) -> None:
    """Write the file; a GIF's frames count on ``bar`` as Pillow encodes them (``units`` each)."""
    frames = getattr(writer, "_frames", None)  # matplotlib's PillowWriter keeps the grabbed frames until finish
    if not (bar.enabled and units and isinstance(frames, list) and frames):
        writer.finish()
        return

    def counted():
        bar.add(units, "encoding")  # the first frame
        for im in frames[1:]:
            yield im
            bar.add(units)

    # PillowWriter.finish's call, with the frames counted as Pillow takes them
    frames[0].save(writer.outfile, save_all=True, append_images=counted(), duration=int(1000 / writer.fps), loop=0)


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
    force: bool = True,
    progress: bool = False,
) -> Path:
    """Animate a joint-space path (e.g. a cross-sector motion) with the muzzle trace.

    Parameters
    ----------
    robot : WearerArm
    waypoints : array_like, shape (K, 4), radians
        Any planner's or the DMP library's path; resampled to ``frames`` configurations evenly
        spaced in joint-space arc length (:func:`resample_path`), so the file size is bounded.
    out_path : path
        ``.gif`` (Pillow, always available) or ``.mp4`` (needs ffmpeg on PATH); ``force=False`` refuses an existing
        file (also one written while the animation was drawn).  Folders made for it are removed again (when empty)
        if the animation is interrupted.
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
    progress : bool
        A progress bar on stderr with the time left (frames drawn, then encoded), shown when the animation takes
        more than 2 s (``tpee-ompl animate`` shows it unless ``--no-progress``).

    Returns
    -------
    Path of the written file.  Frames whose configuration is invalid show the arm in red.
    """
    from matplotlib import animation, rc_context
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    t0 = time.perf_counter()
    W = check_waypoints(robot, waypoints)
    check_int("dpi", dpi, minimum=10, maximum=MAX_ANIMATION_DPI)
    frames = check_int("frames", frames, minimum=2, maximum=MAX_FRAMES)
    if frames * dpi**2 > MAX_FRAME_DPI2:
        raise ValueError(f"frames {frames} at dpi {dpi}: frames x dpi^2 must be at most {MAX_FRAME_DPI2:g} (every "
                         f"frame is held in memory until the file is written): at dpi {dpi} at most "
                         f"{MAX_FRAME_DPI2 // dpi**2} frames")
    fps = check_int("fps", fps, minimum=1, maximum=1000)
    progress = check_bool("progress", progress)
    check_view(elev, azim, dpi)
    out = output_path(out_path, force=force)  # a file name that can be written (not None, a number, bytes)
    suffix = out.suffix.lower()
    if suffix == ".gif":
        writer: Any = animation.PillowWriter(fps=fps)
    elif suffix == ".mp4":
        if not animation.writers.is_available("ffmpeg"):
            raise RuntimeError("writing .mp4 needs ffmpeg on PATH; write a .gif instead (Pillow)")
        writer = animation.FFMpegWriter(fps=fps)
    else:
        raise ValueError(f"unsupported animation format {out.suffix!r}: use .gif or .mp4")
    ta, tb = optional_target(target_a), optional_target(target_b)
    Q = resample_path(W, frames)
    valid = robot.are_valid(Q)
    trace = muzzle_trace(robot, Q)
    targets = [ta if (i < frames / 2 or tb is None) else tb for i in range(frames)]
    targets = [t if t is not None else (ta if ta is not None else tb) for t in targets]
    clear = [robot.line_of_sight_clear(q, t) if t is not None else True for q, t in zip(Q, targets)]
    mesh = scene_mesh(robot)
    arm = [arm_polygons(robot, q, mesh, bool(v)) for q, v in zip(Q, valid)]
    lo, hi = mesh.view_box([*trace, *(t for t in (ta, tb) if t is not None)], 3.0)

    ax = new_axes(figsize=(6.0, 6.0), dpi=dpi)
    fig = ax.figure
    draw_floor(ax, lo, hi)
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
    set_view(ax, lo, hi, elev, azim)
    head = title or "cross-sector motion"
    txt = ax.set_title("", fontsize=9)

    def draw(i: int) -> None:
        coll.set_verts(np.concatenate([mesh.wearer_polys, arm[i][0]]))
        coll.set_facecolor(np.concatenate([mesh.wearer_colors, arm[i][1]]))
        done.set_data_3d(*trace[: i + 1].T)
        if targets[i] is not None:
            end = clip_segment(trace[i], targets[i], lo, hi)
            los.set_data_3d(*np.stack([trace[i], end]).T)
            los.set_color(LOS_CLEAR if clear[i] else LOS_BLOCKED)
        state = "valid" if valid[i] else "INVALID"
        txt.set_text(f"{head}  frame {i + 1}/{frames}  {state}")
        txt.set_color("k" if valid[i] else LOS_BLOCKED)

    encode = _ENCODE_UNITS if suffix == ".gif" else 0
    # interrupted (Ctrl-C), no file and none of the folders made for it are left
    with atomic_path(out, suffix_last=True, force=force) as tmp, \
            rc_context({"savefig.bbox": None}), \
            Progress("animate", frames * (_DRAW_UNITS + encode), progress) as bar:  # (rc as writer.saving sets)
        writer.setup(fig, str(tmp), dpi)  # not writer.saving: it finishes the file also on an error
        try:
            for i in range(frames):
                draw(i)
                writer.grab_frame()
                bar.add(_DRAW_UNITS, f"frame {i + 1}/{frames}")
        except BaseException:
            _abandon(writer)
            raise
        _finish(writer, bar, encode)
    n_bad = int((~valid).sum())
    if n_bad:
        log.warning("animate_path: %d of %d frames are invalid (drawn red)", n_bad, frames)
    log.info("wrote %s (%d frames) in %.1f s", out, frames, time.perf_counter() - t0)
    return out
