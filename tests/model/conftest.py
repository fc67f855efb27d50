"""Fixtures of the model tests: small mesh files for hand-written URDFs."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

_CORNERS = [(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]
_FACES = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
          (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]


@pytest.fixture
def write_cube_stl() -> Callable[[Path, float], Path]:
    """``write_cube_stl(path, side=1.0)`` writes an ASCII STL cube of that side (metres), centred at the origin,
    creating the folders, and returns the path."""

    def write(path: Path, side: float = 1.0) -> Path:
        facets = "".join("facet normal 0 0 0\n outer loop\n" + "".join(
            f"  vertex {side * x:g} {side * y:g} {side * z:g}\n" for x, y, z in (_CORNERS[i] for i in face))
            + " endloop\nendfacet\n" for face in _FACES)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(f"solid cube\n{facets}endsolid cube\n")
        return path

    return write
