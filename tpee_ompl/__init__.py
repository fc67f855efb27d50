"""tpee_ompl: path planning for wearable manipulators with target pointing end effectors, on OMPL.

Implements Zou et al., "A Path Planning Strategy of Wearable Manipulators with Target Pointing
End Effectors", Electronics 2022, 11, 1615.
"""

from .ompl_problem import (
    BatchedMotionValidator,
    WearerValidityChecker,
    array_to_path,
    make_simple_setup,
    make_space,
    motion_states,
    path_to_array,
)
from .robot import WearerArm, default_robot
from .sectors import CROSS_SECTOR_TRAJECTORIES, POSTURE_PRESETS, cross_sector_trajectory, posture_preset

__all__ = [
    "BatchedMotionValidator",
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
