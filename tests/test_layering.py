"""The package's floors: a module imports only from its own folder or from a lower floor, and stays short.

Floors, lowest first: ``validation``/``resources`` -> ``model`` -> ``planning``, ``viz`` ->
``library``, ``examples`` -> ``bench`` -> ``cli``.  Function-level (lazy) imports count too.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "tpee_ompl"
FLOORS = {"validation": 0, "resources": 0, "files": 0, "signals": 0, "model": 1, "planning": 2, "viz": 2, "library": 3, "examples": 3,
          "bench": 4, "cli": 5}
MAX_LINES = 500


def _modules() -> list[Path]:
    return sorted(p for p in PACKAGE.rglob("*.py") if p != PACKAGE / "__init__.py")


def _unit(path: Path) -> str:
    """The floor unit of a module: its top-level folder, or its own name for a top-level module."""
    rel = path.relative_to(PACKAGE)
    return rel.parts[0] if len(rel.parts) > 1 else rel.stem


def _imported_units(path: Path) -> set[str]:
    tree = ast.parse(path.read_text())
    package = path.relative_to(PACKAGE.parent).with_suffix("").parts[:-1]  # e.g. ("tpee_ompl", "bench")
    units = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - node.level + 1]
                target = [*base, *(node.module.split(".") if node.module else [])]
                names = [target] if node.module else [[*target, a.name] for a in node.names]
            elif node.module and node.module.split(".")[0] == "tpee_ompl":
                names = [node.module.split(".")]
            else:
                continue
        elif isinstance(node, ast.Import):
            names = [a.name.split(".") for a in node.names if a.name.split(".")[0] == "tpee_ompl"]
        else:
            continue
        for parts in names:
            if len(parts) >= 2 and parts[0] == "tpee_ompl":
                units.add(parts[1])
    return units


@pytest.mark.parametrize("path", _modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_module_imports_only_its_own_folder_or_lower_floors(path: Path):
    own = _unit(path)
    assert own in FLOORS, f"{own} has no floor: add it to FLOORS"
    bad = {u for u in _imported_units(path) - {own} if u in FLOORS and FLOORS[u] >= FLOORS[own]}
    assert not bad, f"{path.relative_to(PACKAGE)} ({own}, floor {FLOORS[own]}) imports {sorted(bad)}"


@pytest.mark.parametrize("path", _modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_module_stays_under_the_size_limit(path: Path):
    assert len(path.read_text().splitlines()) <= MAX_LINES
