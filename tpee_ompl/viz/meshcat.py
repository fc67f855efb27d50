"""The interactive 3D viewer: Pinocchio's ``MeshcatVisualizer`` (optional extra ``viewer``)."""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from .style import ARM_COLOR, wearer_color

if TYPE_CHECKING:
    from ..model.wearer_arm import WearerArm

__all__ = ["ViewerUnavailableError", "view_meshcat"]

log = logging.getLogger(__name__)


class ViewerUnavailableError(ImportError):
    """The optional interactive viewer (meshcat) is not installed."""


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
        rgb = wearer_color(go.name) if go.parentJoint == 0 else tuple(ARM_COLOR)
        go.meshColor = np.array([*rgb, 1.0])
    viz = MeshcatVisualizer(robot.model, robot.gmodel, vmodel)
    viz.initViewer(open=open_browser, zmq_url=zmq_url, loadModel=True)
    viz.display(q)
    log.info("meshcat viewer at %s", viz.viewer.url())
    return viz
