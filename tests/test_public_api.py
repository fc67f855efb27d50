"""The top-level package exports the public API a user needs first, and nothing it lists is missing."""

from __future__ import annotations

import importlib.metadata

import tpee_ompl


def test_every_name_in_all_is_importable_from_the_top_level():
    missing = [name for name in tpee_ompl.__all__ if not hasattr(tpee_ompl, name)]
    assert not missing


def test_the_headline_names_are_exported():
    for name in ("WearerArm", "DimensionRRT", "DimensionRRTOptions", "tpee_dimension_rrt", "make_simple_setup",
                 "PathLibrary", "Tracker", "aim", "aim_batch", "aim_checked", "load_queries",
                 "RobotChecker", "Obstacle", "panda_shelf", "RobotValidityChecker", "load_joint_query_set"):
        assert name in tpee_ompl.__all__, name


def test_version_has_one_source():
    assert importlib.metadata.version("tpee_ompl") == tpee_ompl.__version__


def test_the_names_static_tools_see_are_the_names_exported_on_first_use():
    """The ``TYPE_CHECKING`` imports (for IDEs and type checkers) name the same objects, from the same modules,
    as the map the package imports them from on first use."""
    import ast
    from pathlib import Path

    tree = ast.parse(Path(tpee_ompl.__file__).read_text())
    block = next(n for n in tree.body if isinstance(n, ast.If) and getattr(n.test, "id", "") == "TYPE_CHECKING")
    static = {a.name: "." + n.module for n in block.body if isinstance(n, ast.ImportFrom) for a in n.names}
    assert static == tpee_ompl._EXPORTS


def test_dir_of_the_package_lists_its_public_names_not_the_helpers_it_imports() -> None:
    """dir(tpee_ompl) also listed Any, TYPE_CHECKING, annotations and importlib (the module's own imports)."""
    import tpee_ompl

    names = set(dir(tpee_ompl))
    assert set(tpee_ompl.__all__) <= names and {"model", "planning", "__version__"} <= names
    assert not names & {"Any", "TYPE_CHECKING", "annotations", "importlib"}
