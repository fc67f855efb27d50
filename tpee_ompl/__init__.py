"""tpee_ompl: path planning for wearable manipulators with target pointing end effectors, on OMPL.

Implements Zou et al., "A Path Planning Strategy of Wearable Manipulators with Target Pointing
End Effectors", Electronics 2022, 11, 1615.

The package is layered, lowest floor first: ``model`` (the wearer and arm, aiming, sectors, query
files) -> ``planning`` (OMPL set-up, paths, dimension-RRT) and ``viz`` -> ``library`` (DMP path
library, tracker) -> ``bench`` (campaigns) -> ``cli``.  What a user needs first is exported here.
"""

from .library.dmp import DMP, DMPOptions, generate, generate_blended, learn_dmp
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

__all__ = [
    # the wearer model and the headline planner
    "WearerArm",
    "default_robot",
    "DimensionRRT",
    "DimensionRRTOptions",
    "tpee_dimension_rrt",
    "make_simple_setup",
    "make_space",
    "WearerValidityChecker",
    "RobotValidityChecker",
    "BatchedMotionValidator",
    # any URDF robot among obstacles
    "RobotChecker",
    "Obstacle",
    "kinova_posts",
    "panda_shelf",
    "JointQuery",
    "load_joint_query_set",
    # aiming, sectors, queries
    "aim",
    "aim_batch",
    "aim_checked",
    "AimingError",
    "BlindAreaError",
    "UnreachableTargetError",
    "select_sector",
    "posture_sector",
    "in_pointing_sector",
    "posture_preset",
    "cross_sector_length_bound",
    "cross_sector_trajectory",
    "CROSS_SECTOR_TRAJECTORIES",
    "POSTURE_PRESETS",
    "SECTOR_PAIRS",
    "Query",
    "QuerySetError",
    "load_queries",
    # paths
    "array_to_path",
    "path_to_array",
    "path_length",
    "motion_states",
    # the real-time layer
    "LibraryDimensionRRT",
    "PathLibrary",
    "QueryResult",
    "LibraryFileError",
    "Tracker",
    "TrackerOptions",
    "make_default_planner",
    "DMP",
    "DMPOptions",
    "learn_dmp",
    "generate",
    "generate_blended",
]

from ._version import __version__ as __version__  # noqa: E402  (one home, floor 0)
