"""Argument checks shared by the options dataclasses: seeds, options with keyword overrides."""

from __future__ import annotations

import pytest

from dataclasses import dataclass

from tpee_ompl.library.dmp import DMPOptions
from tpee_ompl.planning.dimension_rrt_options import DimensionRRTOptions
from tpee_ompl.validation import MAX_SEED, as_float_array, check_name, check_seed, check_type, resolve_options


@pytest.mark.parametrize("seed", [0, -5, MAX_SEED + 1, 10**20, 1.5, True, "3", None])
def test_bad_seeds_are_refused_naming_the_argument(seed):
    with pytest.raises(ValueError, match="seed"):
        check_seed("seed", seed)


def test_seed_range_ends_are_accepted():
    assert check_seed("seed", 1) == 1 and check_seed("seed", MAX_SEED) == MAX_SEED


@dataclass(frozen=True)
class _Options:
    a: int = 1
    b: str = "x"


def test_options_resolve_to_defaults_or_the_given_ones_with_overrides_and_refuse_another_class():
    assert resolve_options(_Options, None, {}) == _Options()
    given = _Options(a=2)
    assert resolve_options(_Options, given, {}) is given
    assert resolve_options(_Options, given, {"b": "y"}) == _Options(a=2, b="y")
    with pytest.raises(ValueError, match="options must be a _Options, got dict"):
        resolve_options(_Options, {"a": 2}, {})
    with pytest.raises(TypeError):
        resolve_options(_Options, None, {"c": 3})


@pytest.mark.parametrize("x", [10**400, [1, 10**400], "1", 1j, ["a"]])
def test_as_float_array_refuses_what_is_not_a_real_float_with_a_value_error(x):
    with pytest.raises(ValueError, match="things must be real numbers"):
        as_float_array(x, "things")


@pytest.mark.parametrize("value", ["my dim\nrrt", "tab\there", "bell\x07"])
def test_names_with_control_characters_are_refused_naming_the_argument(value):
    """A planner named "my dim\\nrrt" broke the benchmark log it was written to (one name per line)."""
    with pytest.raises(ValueError, match="name must be printable text"):
        check_name("name", value)
    with pytest.raises(ValueError, match="name must be printable text"):
        DimensionRRTOptions(name=value)
    assert check_name("name", "Dimension RRT (é)") == "Dimension RRT (é)"


def test_check_type_returns_an_instance_and_names_the_argument_and_the_type_given_otherwise() -> None:
    opts = DMPOptions()
    assert check_type("options", opts, DMPOptions) is opts
    with pytest.raises(ValueError, match=r"^options must be a DMPOptions, got str$"):
        check_type("options", "x", DMPOptions)
