"""Pictures of the wearer and the arm: scene meshes, figures, animations, workspace plots and the meshcat viewer.

Everything draws headless with matplotlib's 3D axes (use the ``Agg`` backend); matplotlib is
imported only inside the drawing functions.  Imports :mod:`tpee_ompl.model` only.

Modules
-------
- :mod:`.style`: colours, lighting, camera defaults.
- :mod:`.meshes`: collision primitives as quads, shading, the cached per-robot scene mesh.
- :mod:`.scene`: :func:`render_scene`, :func:`save_scene`, :func:`render_sectors`.
- :mod:`.animation`: :func:`animate_path`, :func:`resample_path`.
- :mod:`.workspace`: :func:`sector_pointing_range`, :func:`sample_pointing_workspace`,
  :func:`pointing_workspace` (the paper's Fig. 4).
- :mod:`.meshcat`: :func:`view_meshcat` (optional extra ``viewer``).
"""

from .animation import animate_path, resample_path
from .meshcat import ViewerUnavailableError, view_meshcat
from .scene import render_scene, render_sectors, save_scene
from .style import DEFAULT_AZIM, DEFAULT_ELEV, LOS_BLOCKED, LOS_CLEAR, SECTOR_COLORS
from .workspace import PointingSamples, pointing_workspace, sample_pointing_workspace, sector_pointing_range

__all__ = [
    "DEFAULT_AZIM",
    "DEFAULT_ELEV",
    "LOS_BLOCKED",
    "LOS_CLEAR",
    "SECTOR_COLORS",
    "PointingSamples",
    "ViewerUnavailableError",
    "animate_path",
    "pointing_workspace",
    "render_scene",
    "render_sectors",
    "resample_path",
    "sample_pointing_workspace",
    "save_scene",
    "sector_pointing_range",
    "view_meshcat",
]
