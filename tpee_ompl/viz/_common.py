"""Helpers shared by the figure modules: 3D axes set-up, argument checks, writing files.

matplotlib is imported inside the functions, so importing the package stays cheap.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..validation import MAX_JOINT_VALUE, as_float_array

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..model.wearer_arm import WearerArm

log = logging.getLogger(__name__)


# ---------------------------------------------------------------------------- axes
def new_axes(figsize: tuple[float, float] = (7.0, 7.0), dpi: int = 110) -> Axes:
    """3D axes on a new headless Figure (not pyplot: no global state, no display needed)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, dpi=dpi)
    return fig.add_subplot(projection="3d")


MAX_DPI = 600
"""Highest figure resolution (dots per inch): at 2000 a figure's canvas took 1.7 GB; below 10 matplotlib's text
rendering fails (FreeType's "invalid ppem value")."""


def check_view(elev: float, azim: float, dpi: int | None = None) -> None:
    """The camera angles (degrees, finite) and the resolution (dots per inch, 10..``MAX_DPI``; None: no file
    written); ValueError naming the bad one (a NaN angle drew an empty picture)."""
    from ..validation import check_int, check_number

    check_number("elev (degrees)", elev)
    check_number("azim (degrees)", azim)
    if dpi is not None:
        check_int("dpi", dpi, minimum=10, maximum=MAX_DPI)


def set_view(ax: Axes, lo: np.ndarray, hi: np.ndarray, elev: float, azim: float) -> None:
    """Limits [lo, hi] with equal metres per unit on all three axes, the camera, axis labels."""
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(tuple(hi - lo))
    ax.view_init(elev=elev, azim=azim)
    ax.set_xlabel("x (m, forward)")
    ax.set_ylabel("y (m, left)")
    ax.set_zlabel("z (m)")
    ax.tick_params(labelsize=7)


def draw_floor(ax: Axes, lo: np.ndarray, hi: np.ndarray) -> None:
    """A faint grey floor quad at z = lo[2]."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    z = lo[2]
    quad = [[(lo[0], lo[1], z), (hi[0], lo[1], z), (hi[0], hi[1], z), (lo[0], hi[1], z)]]
    ax.add_collection3d(Poly3DCollection(quad, facecolors=(0.85, 0.85, 0.85, 0.35), edgecolors="none"))


def clip_segment(a: np.ndarray, b: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """End point of segment a->b clipped to the box [lo, hi] (a is inside)."""
    d = b - a
    t = 1.0
    for k in range(3):
        if d[k] > 1e-12:
            t = min(t, (hi[k] - a[k]) / d[k])
        elif d[k] < -1e-12:
            t = min(t, (lo[k] - a[k]) / d[k])
    return a + max(t, 0.0) * d


# ---------------------------------------------------------------------------- progress
PROGRESS_DELAY = 2.0
"""Seconds before a drawing's progress bar appears (as ``tpee-ompl track``'s: a quick picture prints none)."""


class Progress:
    """A progress bar on stderr with the time left (tqdm, as ``library build`` and ``track`` show): it counts
    estimated units of work (e.g. microseconds), so phases of unequal cost share one bar and its time left is even.
    ``enabled=False``: every call does nothing.  Use it as a context manager (the bar is closed on leaving)."""

    def __init__(self, desc: str, total: float, enabled: bool) -> None:
        from ..progress import progress_bar

        self.enabled = bool(enabled)
        self._bar = progress_bar(total=total, desc=desc, delay=PROGRESS_DELAY, enabled=self.enabled, counts=False,
                                 bar_format="{desc}: {percentage:3.0f}%|{bar}| {elapsed}<{remaining}{postfix}")

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self._bar.close()

    def add(self, units: float, phase: str | None = None) -> None:
        """``units`` of work done; ``phase`` (shown after the time left) names what runs now."""
        if self.enabled:
            if phase is not None:
                self._bar.set_postfix_str(phase, refresh=False)
            self._bar.update(min(units, max(self._bar.total - self._bar.n, 0)))  # past the total: tqdm shows 0%

    def expect(self, remaining: float) -> None:
        """What is left now, better known than at the start: the total becomes the work done plus ``remaining``."""
        if self.enabled:
            self._bar.total = self._bar.n + remaining  # shown at the next add (refresh() would ignore the delay)


# ---------------------------------------------------------------------------- argument checks
def optional_target(target: Any) -> np.ndarray | None:
    """None, or the target as 3 finite floats (metres) within the model's MAX_TARGET_DISTANCE; ValueError otherwise."""
    from ..model.wearer_arm import check_target_point

    return None if target is None else check_target_point(target)


def check_target_off_muzzle(robot: WearerArm, q: np.ndarray, target: np.ndarray | None) -> None:
    """ValueError naming ``target`` (3,), metres, when it lies at the muzzle of ``robot`` at ``q`` (within the model's
    ``BLIND_TOLERANCE``, 1e-9 m): from there it has no direction, so neither an aim error nor a line of sight."""
    from ..model.pointing import BLIND_TOLERANCE

    if target is None:
        return
    gap = float(np.linalg.norm(target - robot.muzzle(q)[0]))
    if gap <= BLIND_TOLERANCE:
        where = ", ".join(f"{v:.6g}" for v in target)
        raise ValueError(f"target ({where}) m is at the muzzle ({gap:g} m from it): it has no direction to aim at; "
                         "give a target away from the muzzle")


def check_waypoints(robot: WearerArm, waypoints: Any) -> np.ndarray:
    """The waypoints as a finite (K >= 1, robot.nq) float array of joint values within +/-``MAX_JOINT_VALUE``;
    ValueError otherwise (strings and complex numbers refused, not coerced: ``as_float_array``)."""
    W = as_float_array(waypoints, "waypoints")
    if W.ndim != 2 or W.shape[1] != robot.nq or len(W) < 1:
        raise ValueError(f"waypoints must have shape (K, {robot.nq}) with K >= 1; got {W.shape}")
    if not np.all(np.isfinite(W)):
        raise ValueError("waypoints contain NaN or inf")
    if np.abs(W).max() > MAX_JOINT_VALUE:  # no joint travels that far: 1e300 overflowed the drawing's arithmetic
        raise ValueError(f"waypoints hold {np.abs(W).max():g}, beyond the +/-{MAX_JOINT_VALUE:g} rad any joint takes")
    return W


# ---------------------------------------------------------------------------- files
def output_path(out_path: str | os.PathLike, suffixes: tuple[str, ...] | None = None, force: bool = True) -> Path:
    """``out_path`` as a Path that can be written (:func:`~tpee_ompl.files.check_output_path`; its missing folders
    are made when the file is written); ValueError when it is no path, cannot be written or, with ``suffixes``, its
    name ends in none of them.  Nothing is created here: a later argument error leaves no empty folder behind."""
    from ..files import check_output_path

    if not isinstance(out_path, (str, os.PathLike)) or not str(out_path):
        raise ValueError(f"out_path must be a file name, got {out_path!r}")
    out = Path(out_path)
    if suffixes is not None:
        _check_image_suffix(out, suffixes)
    return check_output_path(out, force=force, what="figure file")


def _check_image_suffix(out: Path, suffixes: tuple[str, ...]) -> None:
    if out.suffix.lower() not in suffixes:
        raise ValueError(f"figure file {out}: give a name ending in an image suffix ({', '.join(suffixes[:4])}, ...)")


def image_suffixes() -> tuple[str, ...]:
    """The file suffixes a figure can be written as (``.png``, ``.pdf``, ``.svg``, ...: matplotlib's but ``.pgf``)."""
    from matplotlib.backend_bases import FigureCanvasBase

    common = (".png", ".pdf", ".svg", ".jpg")
    # not .pgf: matplotlib writes it through LaTeX (xelatex), failing after the drawing where LaTeX is missing
    others = sorted("." + k for k in FigureCanvasBase.get_supported_filetypes() if "." + k not in (*common, ".pgf"))
    return (*common, *others)


def write_figure(fig: Figure, out: Path, dpi: int, force: bool = True, **savefig_kwargs: Any) -> Path:
    """Save ``fig`` to exactly ``out`` (format from its suffix), atomically; log it and return ``out``.

    A name without a known image suffix is refused (matplotlib would add ``.png`` and write another
    file than the one named); an existing file is replaced in one step, never left half-written (``force=False``:
    refused, also one written meanwhile); folders made for it are removed again if the write does not complete
    (:func:`~tpee_ompl.files.atomic_path`).
    """
    from ..files import atomic_path

    _check_image_suffix(out, image_suffixes())
    ps = logging.getLogger("matplotlib.backends.backend_ps")
    level = ps.level
    ps.setLevel(logging.ERROR)  # .eps/.ps: "does not support transparency" for the scene's translucent faces
    try:
        with atomic_path(out, force=force) as tmp:
            fig.savefig(tmp, dpi=dpi, format=out.suffix[1:].lower(), **savefig_kwargs)
    finally:
        ps.setLevel(level)
    log.info("wrote %s", out)
    return out
