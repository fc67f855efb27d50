"""The package's floors: a module imports only from its own folder or from a lower floor, and stays short.

Floors, lowest first: ``validation``/``resources`` -> ``model`` -> ``planning``, ``viz`` ->
``library``, ``examples`` -> ``bench`` -> ``cli``.  Function-level (lazy) imports count too.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "tpee_ompl"
FLOORS = {"_version": 0, "validation": 0, "resources": 0, "files": 0, "signals": 0, "progress": 0, "model": 1, "planning": 2, "viz": 2, "library": 3, "examples": 3,
          "bench": 4, "cli": 5, "__init__": 5, "_launch": 6, "__main__": 7}
MAX_LINES = 500


def _modules() -> list[Path]:
    return sorted(p for p in PACKAGE.rglob("*.py") if p != PACKAGE / "__init__.py")


def _unit(path: Path) -> str:
    """The floor unit of a module: its top-level folder, or its own name for a top-level module."""
    rel = path.relative_to(PACKAGE)
    return rel.parts[0] if len(rel.parts) > 1 else rel.stem


def _imported_units(path: Path) -> set[str]:
    package = path.relative_to(PACKAGE.parent).with_suffix("").parts[:-1]  # e.g. ("tpee_ompl", "bench")
    return _units_of(path.read_text(), package)


def _units_of(source: str, package: tuple[str, ...]) -> set[str]:
    """The floor units a module's source imports, the module being in ``package``."""
    tree = ast.parse(source)
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
            if parts[0] != "tpee_ompl":
                continue
            if len(parts) >= 2 and _is_unit(parts[1]):
                units.add(parts[1])
            else:  # the top-level package itself (``import tpee_ompl``, ``from .. import name``): it imports every floor
                units.add(TOP)
    return units


TOP = "__init__"
"""The top-level package as an import target: it exports the public API from every floor below the CLI."""


def _is_unit(name: str) -> bool:
    return (PACKAGE / name).is_dir() or (PACKAGE / f"{name}.py").is_file()


@pytest.mark.parametrize("path", _modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_module_imports_only_its_own_folder_or_lower_floors(path: Path):
    own = _unit(path)
    assert own in FLOORS, f"{own} has no floor: add it to FLOORS"
    bad = {u for u in _imported_units(path) - {own} if u in FLOORS and FLOORS[u] >= FLOORS[own]}
    assert not bad, f"{path.relative_to(PACKAGE)} ({own}, floor {FLOORS[own]}) imports {sorted(bad)}"


@pytest.mark.parametrize("path", _modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_module_stays_under_the_size_limit(path: Path):
    assert len(path.read_text().splitlines()) <= MAX_LINES


@pytest.mark.parametrize("source", ["import tpee_ompl", "from tpee_ompl import WearerArm", "from .. import __version__",
                                    "import tpee_ompl.bench"])
def test_an_import_of_the_top_level_package_or_a_higher_floor_counts_against_a_lower_one(source: str):
    units = _units_of(source, ("tpee_ompl", "model"))
    assert units & {TOP, "bench"} and any(FLOORS[u] > FLOORS["model"] for u in units)
