"""Hypothesis strategies and settings shared by the property-based tests (adversarial inputs).

For every input the rule is the same: a correct result, or the documented exception type with a
message that names the bad value or parameter.  Never a crash, a hang or a silently wrong answer.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import HealthCheck, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from tpee_ompl.model.pointing import default_geometry
from tpee_ompl.model.sectors import SECTORS, posture_preset
from tpee_ompl.model.wearer_arm import MAX_TARGET_DISTANCE, WearerArm

SETTINGS = settings(
    max_examples=60, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
FEW = settings(SETTINGS, max_examples=25)

SPECIAL = [math.nan, math.inf, -math.inf, 1e300, -1e300, 1e308, -0.0, 5e-324, MAX_TARGET_DISTANCE * 1.01]
numbers = st.one_of(st.floats(-10, 10), st.sampled_from(SPECIAL), st.floats(allow_nan=True, allow_infinity=True))


def names_bad_value(msg: str, value: np.ndarray) -> bool:
    """The message shows a non-finite value, or the offending number, or the failing rule."""
    low = msg.lower()
    if "shape" in low:
        return True
    if not np.all(np.isfinite(value)):
        return "nan" in low or "inf" in low
    return any(k in low for k in ("shape", "farther", "max_target_distance", "limits", "finite"))



configs = st.one_of(
    hnp.arrays(float, st.sampled_from([(4,), (3,), (5,), (0,), (2, 2), (1, 4)]), elements=numbers),
    hnp.arrays(float, (4,), elements=st.floats(-4, 4)),
)

targets = st.one_of(
    hnp.arrays(float, (3,), elements=numbers),
    hnp.arrays(float, (3,), elements=st.floats(-15, 15)),
    st.sampled_from(["pivot", "torso", "head", "blind"]),
)


def resolve_target(robot: WearerArm, t: np.ndarray | str, k: int = 3) -> np.ndarray:
    """Resolve the named adversarial targets: the pivot, inside the body, in posture k's blind area."""
    if not isinstance(t, str):
        return t
    g = default_geometry()
    if t == "pivot":
        return g.pivot.copy()
    if t == "blind":
        origin, rot = g.pan_frame(posture_preset(k))
        return origin[0] + rot[0][:, 2] * 2.0  # on the pan axis, 2 m out
    go = robot.gmodel.geometryObjects[robot.gmodel.getGeometryId(f"{t}_0")]
    return go.placement.translation.copy()


postures = st.one_of(
    st.sampled_from(SECTORS),
    st.integers(-2, 7),
    hnp.arrays(float, (2,), elements=st.one_of(st.floats(-4, 4), st.sampled_from([math.nan, math.inf]))),
)
