"""Environment obstacles for a :class:`~tpee_ompl.model.robot_checker.RobotChecker`: fixed Coal shapes.

An obstacle is a geometry on Pinocchio's universe joint: paired with every robot geometry that
can move, never with another obstacle or the fixed base.  Sizes are full lengths in metres.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin

from ..validation import as_float_array, check_name

__all__ = ["MAX_SIZE", "MIN_SIZE", "OBSTACLE_SHAPES", "Obstacle", "box"]

MIN_SIZE, MAX_SIZE = 1e-6, 1e4
"""Metres: obstacle sizes accepted.  Beyond 1e4 m Coal's distances to a small link lose accuracy (a 1e6-m box
gave false collisions 2 cm away)."""
MIN_MESH_SCALE, MAX_MESH_SCALE = 1e-6, 1e4
"""Mesh scale factors accepted (a scale of 1e-20 gave negative clearances for a valid state)."""
OBSTACLE_SHAPES = {"box": 3, "sphere": 1, "capsule": 2, "cylinder": 2, "mesh": 3}
"""Shape -> number of size values: box (x, y, z lengths), sphere (radius), capsule and cylinder
(radius, length along local z), mesh (x, y, z scale of the file's vertices)."""


@dataclass(frozen=True, eq=False)
class Obstacle:
    """A fixed obstacle.

    Attributes
    ----------
    name : str
        Its geometry name (unique in the checker).
    shape : {"box", "sphere", "capsule", "cylinder", "mesh"}
        A cylinder stays a Coal cylinder (URDF cylinders may become capsules; obstacles do not).
    size : sequence of floats, metres (see :data:`OBSTACLE_SHAPES`)
    placement : pin.SE3, 4x4 homogeneous matrix or 3 numbers (a translation), world frame
    mesh : path of a mesh file Coal can read (shape "mesh" only).  Coal checks a mesh as its surface: a link
        entirely inside a closed mesh is not in collision with it (a motion cannot cross the surface, so a
        path from a state outside never gets in; a start or goal inside is not refused).  Give a solid
        obstacle as a box, sphere, capsule or cylinder where one fits.
    """

    name: str
    shape: str
    size: tuple[float, ...]
    placement: object = field(default=(0.0, 0.0, 0.0))
    mesh: str | os.PathLike | None = None

    def __post_init__(self) -> None:
        check_name("obstacle name", self.name)
        if not isinstance(self.shape, str) or self.shape not in OBSTACLE_SHAPES:
            raise ValueError(f"obstacle {self.name!r}: shape must be one of {sorted(OBSTACLE_SHAPES)}, got {self.shape!r}")
        n = OBSTACLE_SHAPES[self.shape]
        size = as_float_array(self.size, f"obstacle {self.name!r} size")
        if size.shape != (n,) or not np.all(np.isfinite(size)) or not np.all(size > 0):
            raise ValueError(f"obstacle {self.name!r}: a {self.shape} needs {n} finite sizes > 0 (metres), got {self.size!r}")
        lo, hi = (MIN_MESH_SCALE, MAX_MESH_SCALE) if self.shape == "mesh" else (MIN_SIZE, MAX_SIZE)
        if np.any(size < lo) or np.any(size > hi):  # Coal's GJK loses its accuracy beyond (false collisions)
            raise ValueError(f"obstacle {self.name!r}: {'mesh scale' if self.shape == 'mesh' else 'sizes'} must lie in "
                             f"[{lo:g}, {hi:g}], got {self.size!r}")
        object.__setattr__(self, "size", tuple(float(v) for v in size))
        object.__setattr__(self, "placement", _as_placement(self.placement, self.name))
        if (self.shape == "mesh") != (self.mesh is not None):
            raise ValueError(f"obstacle {self.name!r}: give mesh (a file) exactly when shape is 'mesh'")
        if self.mesh is not None:
            if not isinstance(self.mesh, (str, os.PathLike)):
                raise ValueError(f"obstacle {self.name!r}: mesh must be a path, got {self.mesh!r}")
            if not Path(self.mesh).is_file():
                raise FileNotFoundError(f"obstacle {self.name!r}: mesh file not found: {self.mesh}")

    def geometry(self) -> coal.CollisionGeometry:
        """A new Coal geometry of this shape (centred on its origin)."""
        s = self.size
        if self.shape == "box":
            return coal.Box(*s)
        if self.shape == "sphere":
            return coal.Sphere(s[0])
        if self.shape == "capsule":
            return coal.Capsule(s[0], s[1])
        if self.shape == "cylinder":
            return coal.Cylinder(s[0], s[1])
        return coal.MeshLoader().load(str(self.mesh), np.array(s))

    def describe(self) -> str:
        """A canonical one-line description (it enters the checker's model hash)."""
        m = np.asarray(self.placement.homogeneous).round(12).tolist()
        return f"{self.name}:{self.shape}:{list(self.size)}:{m}:{self.mesh or ''}"


def box(name: str, size: tuple[float, float, float], centre: tuple[float, float, float]) -> Obstacle:
    """An axis-aligned box of full lengths ``size`` centred at ``centre`` (metres)."""
    return Obstacle(name, "box", size, centre)


def _as_placement(p: object, name: str) -> pin.SE3:
    if isinstance(p, pin.SE3):
        M = p.homogeneous
    else:
        a = as_float_array(p, f"obstacle {name!r} placement")
        if a.shape == (3,):
            M = np.eye(4)
            M[:3, 3] = a
        elif a.shape == (4, 4):
            M = a
        else:
            raise ValueError(f"obstacle {name!r}: placement must be a pin.SE3, a 4x4 matrix or 3 numbers, got shape {a.shape}")
    R = M[:3, :3]
    if not (np.all(np.isfinite(M)) and np.allclose(R @ R.T, np.eye(3), atol=1e-9) and np.linalg.det(R) > 0
            and np.allclose(M[3], [0, 0, 0, 1])):
        raise ValueError(f"obstacle {name!r}: placement must be finite with a proper rotation")
    return pin.SE3(R.copy(), M[:3, 3].copy())
