"""Robots beyond the wearer: the Franka Panda among a table and a shelf, and a Kinova arm with continuous joints
between two posts.

The Panda's files come from the optional ``robots`` extra (``example-robot-data``):
``panda_collision.urdf`` (spheres and cylinders, loaded as capsules; fast) with ``panda.srdf``,
both fingers locked.  Its base (z = 0, the world frame) stands on a 12 cm pedestal on a table
(top at z = -0.12: link 1's collision spheres reach 9 cm below the base); a shelf stands on the
table in front of it (+x), two compartments high with a divider, so that going from one compartment to another, or from the table beside the
shelf into it, needs planning.

The Kinova Jaco2 6-DOF arm (``kinova.urdf`` of ``example-robot-data``: joints 1, 4 and 6 continuous, planned as
SO2 angles; meshes checked as their convex hulls, as MoveIt users' convex collision meshes) stands between two
posts; its SRDF (packaged: ``kinova_posts.srdf``, from ``experiments/make_kinova_queries.py``) disables the link
pairs touching in at least 95 % of random configurations, as the MoveIt setup assistant's "always" pairs (the
shipped SRDF disables none, so every configuration collided).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..resources import model_file
from .obstacles import Obstacle, box
from .robot_checker import RobotChecker

__all__ = [
    "kinova_files",
    "KINOVA_GROUPS",
    "KINOVA_POSTS",
    "kinova_posts",
    "panda_files",
    "PANDA_GROUPS",
    "PANDA_LOCKED",
    "panda_region",
    "panda_shelf",
    "PANDA_SHELF_OBSTACLES",
    "PANDA_SHELF_REGIONS",
    "PANDA_TOOL_FRAME",
]

PANDA_GROUPS = ((0, 1, 2), (3, 4, 5, 6))
"""Joint groups for dimension-RRT: shoulder and upper arm (reach), then elbow and wrist (orientation)."""
PANDA_LOCKED = {"panda_finger_joint1": 0.02, "panda_finger_joint2": 0.02}
"""The fingers, half open (metres), are not planned."""
PANDA_TOOL_FRAME = "panda_hand_tcp"
"""The frame between the fingertips: the end-effector point the query labels use."""
PANDA_SECURITY_MARGIN = 0.02
"""Metres: the default margin of :func:`panda_shelf`, as the wearer's (the motion-check step is then 0.0093 rad)."""
_EXTRA_MESSAGE = "the Panda needs the optional 'robots' extra: pip install 'tpee-ompl[robots]'"

_SHELF_FRONT, _SHELF_BACK, _SHELF_HALF_WIDTH = 0.42, 0.77, 0.46
_BOARD = 0.02  # board and wall thickness
TABLE_Z = -0.12
_LEVELS = (TABLE_Z, 0.28, 0.68)  # top faces of the table and the two boards, metres
_HEIGHT = _LEVELS[-1] - TABLE_Z
_MID = (_LEVELS[-1] + TABLE_Z) / 2

PANDA_SHELF_OBSTACLES: tuple[Obstacle, ...] = (
    box("table", (1.3, 1.8, 0.04), (0.30, 0.0, TABLE_Z - 0.02)),
    *(box(f"board_{k}", (_SHELF_BACK - _SHELF_FRONT, 2 * _SHELF_HALF_WIDTH, _BOARD),
          ((_SHELF_FRONT + _SHELF_BACK) / 2, 0.0, z - _BOARD / 2)) for k, z in enumerate(_LEVELS[1:], 1)),
    *(box(f"wall_{side}", (_SHELF_BACK - _SHELF_FRONT, _BOARD, _HEIGHT),
          ((_SHELF_FRONT + _SHELF_BACK) / 2, s * (_SHELF_HALF_WIDTH + _BOARD / 2), _MID))
      for side, s in (("left", 1), ("right", -1))),
    box("divider", (_SHELF_BACK - _SHELF_FRONT, _BOARD, _HEIGHT), ((_SHELF_FRONT + _SHELF_BACK) / 2, 0.0, _MID)),
    box("back", (_BOARD, 2 * _SHELF_HALF_WIDTH + 2 * _BOARD, _HEIGHT), (_SHELF_BACK + _BOARD / 2, 0.0, _MID)),
)
"""The scene (metres, world = the Panda's base frame): table, two boards, two side walls, a divider, a back."""


def _compartments() -> dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]]:
    out = {}
    for name, (z0, z1) in zip(("low", "high"), zip(_LEVELS[:-1], _LEVELS[1:])):
        top = z1 - _BOARD
        out[f"shelf_{name}_left"] = ((_SHELF_FRONT + 0.03, 0.06, z0 + 0.04), (_SHELF_BACK - 0.04, _SHELF_HALF_WIDTH - 0.04, top - 0.04))
        out[f"shelf_{name}_right"] = ((_SHELF_FRONT + 0.03, -_SHELF_HALF_WIDTH + 0.04, z0 + 0.04), (_SHELF_BACK - 0.04, -0.06, top - 0.04))
    out["shelf_top"] = ((_SHELF_FRONT + 0.03, -0.3, _LEVELS[-1] + 0.05), (_SHELF_BACK - 0.04, 0.3, _LEVELS[-1] + 0.30))
    out["table_left"] = ((0.15, 0.50, TABLE_Z + 0.04), (0.60, 0.85, TABLE_Z + 0.35))
    out["table_right"] = ((0.15, -0.85, TABLE_Z + 0.04), (0.60, -0.50, TABLE_Z + 0.35))
    return out


PANDA_SHELF_REGIONS = _compartments()
"""Label -> (lower corner, upper corner) of the box the tool point must be in (metres): the six
shelf compartments (levels low/high, sides left (+y)/right), the shelf's top and the table on either side."""


def panda_files() -> tuple[Path, Path]:
    """The Panda's collision URDF and SRDF from ``example-robot-data``.

    Raises ImportError naming the ``robots`` extra when it is not installed."""
    sub = "panda_description/urdf/panda_collision.urdf"
    robots = _robots_folder(sub, _EXTRA_MESSAGE)
    return robots / sub, robots / "panda_description/srdf/panda.srdf"


def _robots_folder(sub: str, missing: str) -> Path:
    """``example-robot-data``'s folder holding ``sub``; ImportError with the message ``missing`` without it."""
    try:
        import example_robot_data
    except ImportError as exc:
        raise ImportError(missing) from exc
    return Path(example_robot_data.getModelPath(sub))


def panda_shelf(n_threads: int | None = None, security_margin: float = PANDA_SECURITY_MARGIN) -> RobotChecker:
    """The Panda (7 joints, fingers locked) on a table with a two-board, two-sided shelf in front."""
    urdf, srdf = panda_files()
    return RobotChecker(urdf, srdf, security_margin=security_margin, n_threads=n_threads,
                        obstacles=PANDA_SHELF_OBSTACLES, locked=PANDA_LOCKED, extra_points=(PANDA_TOOL_FRAME,))


def panda_region(checker: RobotChecker, q: np.ndarray) -> str | None:
    """The :data:`PANDA_SHELF_REGIONS` label whose box holds the tool point at q, or None."""
    p = checker.frame_placement(q, PANDA_TOOL_FRAME).translation
    for label, (lo, hi) in PANDA_SHELF_REGIONS.items():
        if np.all(p >= lo) and np.all(p <= hi):
            return label
    return None


KINOVA_GROUPS = ((0, 1, 2), (3, 4, 5))
"""Joint groups for dimension-RRT: shoulder and elbow (reach), then the wrist (orientation)."""
KINOVA_POSTS: tuple[Obstacle, ...] = (
    box("post_front", (0.06, 0.06, 1.2), (0.3, 0.0, 0.4)),
    box("post_back", (0.06, 0.06, 1.2), (-0.3, 0.0, 0.4)),
)
"""Two posts 0.3 m either side of the base (63 % of random configurations free; the straight motion between two
free configurations collides about two times in three)."""
KINOVA_SRDF = "kinova_posts.srdf"
"""The packaged SRDF of :func:`kinova_posts` (``experiments/make_kinova_queries.py`` writes it)."""
_KINOVA_EXTRA_MESSAGE = "the Kinova arm needs the optional 'robots' extra: pip install 'tpee-ompl[robots]'"


def kinova_files() -> tuple[Path, list[str]]:
    """The Kinova Jaco2 6-DOF arm's URDF from ``example-robot-data`` and the package folder its meshes are in.

    Raises ImportError naming the ``robots`` extra when it is not installed."""
    sub = "kinova_description/robots/kinova.urdf"
    robots = _robots_folder(sub, _KINOVA_EXTRA_MESSAGE)
    return robots / sub, [str((robots / "../..").resolve())]


def kinova_posts(n_threads: int | None = None, srdf: str | Path | None = None) -> RobotChecker:
    """The Kinova arm (3 continuous joints, convex hulls) between :data:`KINOVA_POSTS`, with the packaged SRDF
    (or ``srdf``)."""
    urdf, dirs = kinova_files()
    return RobotChecker(urdf, model_file(KINOVA_SRDF) if srdf is None else srdf, n_threads=n_threads,
                        obstacles=KINOVA_POSTS, package_dirs=dirs, convex_meshes=True)
