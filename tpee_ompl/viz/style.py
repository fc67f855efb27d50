"""Colours, lighting and camera defaults shared by every figure of :mod:`tpee_ompl.viz`."""

from __future__ import annotations

import numpy as np

__all__ = [
    "ARM_COLOR",
    "BARREL_COLOR",
    "DEFAULT_AZIM",
    "DEFAULT_ELEV",
    "INVALID_COLOR",
    "LIGHT",
    "LOS_BLOCKED",
    "LOS_CLEAR",
    "SECTOR_COLORS",
    "SILHOUETTE",
    "hex_rgb",
    "wearer_color",
]

SECTOR_COLORS = {1: "#1f77b4", 2: "#ff7f0e", 3: "#2ca02c", 4: "#9467bd"}
"""Posture sector -> matplotlib colour, shared by every figure."""

DEFAULT_ELEV = 18.0
"""Degrees: default camera elevation."""
DEFAULT_AZIM = -125.0
"""Degrees: default camera azimuth (from behind the wearer's right shoulder, so the arm on the back shows)."""

LOS_CLEAR = "#16a34a"
"""Colour of a clear line of sight (green)."""
LOS_BLOCKED = "#dc2626"
"""Colour of a blocked line of sight, and of the title of an invalid configuration (red)."""

ARM_COLOR = np.array([0.10, 0.35, 0.80])
BARREL_COLOR = np.array([0.05, 0.15, 0.45])
INVALID_COLOR = np.array([0.90, 0.08, 0.08])
SILHOUETTE = (0.2, 0.2, 0.2, 0.08)
"""RGBA of the wearer's projected faces in the 2D workspace views."""
LIGHT = np.array([-0.35, -0.55, 0.76]) / np.linalg.norm([-0.35, -0.55, 0.76])
"""Unit direction of the light used for shading faces."""

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


def wearer_color(name: str) -> tuple[float, float, float]:
    """RGB of a wearer geometry, chosen by the prefix of its name (``"<link>_<i>"``)."""
    for prefix, rgb in _WEARER_COLORS.items():
        if name.startswith(prefix):
            return rgb
    return _WEARER_DEFAULT


def hex_rgb(color: str) -> tuple[float, float, float]:
    """RGB triple of a matplotlib colour (e.g. ``"#1f77b4"``)."""
    from matplotlib.colors import to_rgb

    return to_rgb(color)
