"""tpee_ompl: path planning for wearable manipulators with target pointing end effectors, on OMPL.

Implements Zou et al., "A Path Planning Strategy of Wearable Manipulators with Target Pointing
End Effectors", Electronics 2022, 11, 1615.

The package is layered, lowest floor first: ``model`` (the wearer and arm, aiming, sectors, query
files) -> ``planning`` (OMPL set-up, paths, dimension-RRT) and ``viz`` -> ``library`` (DMP path
library, tracker) -> ``bench`` (campaigns) -> ``cli``.  What a user needs first is exported here.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from ._version import __version__ as __version__  # (one home, floor 0)

if TYPE_CHECKING:  # what static tools see; at run time the names are imported on first use (below)
    from .library.dmp import DMP, DMPOptions, generate, generate_blended, learn_dmp, min_samples
    from .library import (
        LibraryDimensionRRT,
        LibraryFileError,
        PathLibrary,
        QueryResult,
        Tracker,
        TrackerOptions,
        make_default_planner,
    )
    from .model.pointing import AimingError, BlindAreaError, UnreachableTargetError, aim, aim_batch, aim_checked
    from .model.joint_queries import JointQuery, load_joint_query_set
    from .model.obstacles import Obstacle
    from .model.queries import Query, QuerySetError, load_queries
    from .model.robot_checker import RobotChecker
    from .model.robots import kinova_posts, panda_shelf
    from .model.sectors import (
        CROSS_SECTOR_TRAJECTORIES,
        POSTURE_PRESETS,
        SECTOR_PAIRS,
        cross_sector_length_bound,
        cross_sector_trajectory,
        in_pointing_sector,
        posture_preset,
        posture_sector,
        select_sector,
    )
    from .model.wearer_arm import WearerArm, default_robot
    from .planning.dimension_rrt import DimensionRRT, DimensionRRTOptions
    from .planning.paths import array_to_path, motion_states, path_length, path_to_array
    from .planning.setup import (
        BatchedMotionValidator,
        RobotValidityChecker,
        WearerValidityChecker,
        make_simple_setup,
        make_space,
    )
    from .planning.tpee import tpee_dimension_rrt


_EXPORTS = {
    # the wearer model and the headline planner
    "WearerArm": ".model.wearer_arm",
    "default_robot": ".model.wearer_arm",
    "DimensionRRT": ".planning.dimension_rrt",
    "DimensionRRTOptions": ".planning.dimension_rrt",
    "tpee_dimension_rrt": ".planning.tpee",
    "make_simple_setup": ".planning.setup",
    "make_space": ".planning.setup",
    "WearerValidityChecker": ".planning.setup",
    "RobotValidityChecker": ".planning.setup",
    "BatchedMotionValidator": ".planning.setup",
    # any URDF robot among obstacles
    "RobotChecker": ".model.robot_checker",
    "Obstacle": ".model.obstacles",
    "kinova_posts": ".model.robots",
    "panda_shelf": ".model.robots",
    "JointQuery": ".model.joint_queries",
    "load_joint_query_set": ".model.joint_queries",
    # aiming, sectors, queries
    "aim": ".model.pointing",
    "aim_batch": ".model.pointing",
    "aim_checked": ".model.pointing",
    "AimingError": ".model.pointing",
    "BlindAreaError": ".model.pointing",
    "UnreachableTargetError": ".model.pointing",
    "select_sector": ".model.sectors",
    "posture_sector": ".model.sectors",
    "in_pointing_sector": ".model.sectors",
    "posture_preset": ".model.sectors",
    "cross_sector_length_bound": ".model.sectors",
    "cross_sector_trajectory": ".model.sectors",
    "CROSS_SECTOR_TRAJECTORIES": ".model.sectors",
    "POSTURE_PRESETS": ".model.sectors",
    "SECTOR_PAIRS": ".model.sectors",
    "Query": ".model.queries",
    "QuerySetError": ".model.queries",
    "load_queries": ".model.queries",
    # paths
    "array_to_path": ".planning.paths",
    "path_to_array": ".planning.paths",
    "path_length": ".planning.paths",
    "motion_states": ".planning.paths",
    # the real-time layer
    "LibraryDimensionRRT": ".library",
    "PathLibrary": ".library",
    "QueryResult": ".library",
    "LibraryFileError": ".library",
    "Tracker": ".library",
    "TrackerOptions": ".library",
    "make_default_planner": ".library",
    "DMP": ".library.dmp",
    "DMPOptions": ".library.dmp",
    "learn_dmp": ".library.dmp",
    "min_samples": ".library.dmp",
    "generate": ".library.dmp",
    "generate_blended": ".library.dmp",
}
"""Public name -> the module it lives in (imported on first use, so that ``import tpee_ompl``, and the command
line's start, do not load OMPL, Pinocchio and Coal before they are needed)."""

__all__ = list(_EXPORTS)

_SUBPACKAGES = frozenset({"model", "planning", "library", "bench", "cli", "viz", "examples"})


def __getattr__(name: str) -> Any:
    """A public name's object, or a subpackage, imported on first use and kept (PEP 562)."""
    if name in _EXPORTS:
        value = getattr(importlib.import_module(_EXPORTS[name], __name__), name)
    elif name in _SUBPACKAGES:
        value = importlib.import_module(f".{name}", __name__)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """The public names, the subpackages and the module's dunders (not the helpers it imports: ``Any``, ``importlib``)."""
    return sorted({n for n in globals() if n.startswith("__")} | set(__all__) | _SUBPACKAGES)
