"""tpee_ompl: path planning for wearable manipulators with target pointing end effectors, on OMPL.

Implements Zou et al., "A Path Planning Strategy of Wearable Manipulators with Target Pointing
End Effectors", Electronics 2022, 11, 1615.
"""

from .planning.setup import BatchedMotionValidator, WearerValidityChecker, make_simple_setup, make_space
from .planning.paths import array_to_path, motion_states, path_to_array
from .library.dmp import DMP, DMPOptions, generate, generate_blended, learn_dmp
from .library.path_library import LibraryFileError, PathLibrary, QueryResult
from .model.pointing import AimingError, BlindAreaError, UnreachableTargetError, aim, aim_batch, aim_checked
from .model.queries import Query, load_queries
from .model.wearer_arm import WearerArm, default_robot
from .model.sectors import (
    CROSS_SECTOR_TRAJECTORIES,
    POSTURE_PRESETS,
    cross_sector_trajectory,
    in_pointing_sector,
    posture_preset,
    posture_sector,
    select_sector,
)
from .library.tracker import Tracker, make_default_planner

__all__ = [
    "AimingError",
    "BatchedMotionValidator",
    "BlindAreaError",
    "DMP",
    "DMPOptions",
    "LibraryFileError",
    "PathLibrary",
    "Query",
    "QueryResult",
    "Tracker",
    "UnreachableTargetError",
    "aim",
    "aim_batch",
    "aim_checked",
    "generate",
    "generate_blended",
    "in_pointing_sector",
    "learn_dmp",
    "load_queries",
    "make_default_planner",
    "posture_sector",
    "select_sector",
    "CROSS_SECTOR_TRAJECTORIES",
    "POSTURE_PRESETS",
    "WearerArm",
    "WearerValidityChecker",
    "array_to_path",
    "cross_sector_trajectory",
    "default_robot",
    "make_simple_setup",
    "make_space",
    "motion_states",
    "path_to_array",
    "posture_preset",
]

__version__ = "0.1.0"
