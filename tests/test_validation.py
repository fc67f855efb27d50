"""Argument checks shared by the options dataclasses: seeds."""

from __future__ import annotations

import pytest

from tpee_ompl.validation import MAX_SEED, check_seed


@pytest.mark.parametrize("seed", [0, -5, MAX_SEED + 1, 10**20, 1.5, True, "3", None])
def test_bad_seeds_are_refused_naming_the_argument(seed):
    with pytest.raises(ValueError, match="seed"):
        check_seed("seed", seed)


def test_seed_range_ends_are_accepted():
    assert check_seed("seed", 1) == 1 and check_seed("seed", MAX_SEED) == MAX_SEED
