"""Tests of the DMP maths (eqs. 12-17): reproduction, exact goal convergence, goal == start, closed-form generation."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from tpee_ompl.library.dmp import (
    DMPOptions,
    basis_functions,
    blend_forward_reverse,
    canonical_phase,
    generate,
    generate_blended,
    integrate,
    learn_dmp,
)
from tpee_ompl.planning.paths import resample_waypoints


def _demo(rng: np.random.Generator, steps: int = 7, per_step: int = 100, scale: float = 0.6) -> np.ndarray:
    """A 2-D demo like the library's: random waypoints, straight segments, quintic in fake time."""
    return resample_waypoints(np.cumsum(rng.uniform(-scale, scale, (steps, 2)), axis=0), per_step)


@pytest.mark.parametrize("seed", range(5))
def test_dmp_reproduces_its_demonstration_within_1e3_rad(seed: int) -> None:
    demo = _demo(np.random.default_rng(seed))
    dmp = learn_dmp(demo)
    assert np.abs(generate(dmp, demo[0], demo[-1]) - demo).max() < 1e-3


def test_closed_form_rollout_equals_step_by_step_integration(rng: np.random.Generator) -> None:
    demo = _demo(rng)
    dmp = learn_dmp(demo)
    x = canonical_phase(dmp.n_steps, dmp.options.alpha_x)
    phi = basis_functions(x, dmp.weights.shape[1], dmp.options.alpha_x, dmp.options.width, normalized=True)
    start, goal = demo[0] + [0.2, -0.1], demo[-1] + [-0.3, 0.4]
    S = np.where(dmp.scaled, goal - start, 1.0)
    reference = integrate(start, goal, (phi @ dmp.weights.T) * x[:, None] * S, dmp.options)
    np.testing.assert_allclose(generate(dmp, start, goal), reference, atol=1e-7)


@pytest.mark.parametrize("scaling", ["amplitude", "none"])
def test_rollout_ends_exactly_at_a_new_goal(rng: np.random.Generator, scaling: str) -> None:
    dmp = learn_dmp(_demo(rng), DMPOptions(scaling=scaling))
    starts = rng.uniform(-1.5, 1.5, (50, 2))
    goals = rng.uniform(-1.5, 1.5, (50, 2))
    Y = generate(dmp, starts, goals)
    assert Y.shape == (50, dmp.n_steps, 2)
    assert np.array_equal(Y[:, 0], starts)
    assert np.array_equal(Y[:, -1], goals)
    # the assignment of the end point only removes a residual the dynamics already made tiny
    x = canonical_phase(dmp.n_steps, dmp.options.alpha_x)
    phi = basis_functions(x, dmp.weights.shape[1], dmp.options.alpha_x, dmp.options.width, normalized=True)
    S = np.where(dmp.scaled, goals - starts, 1.0)
    raw = integrate(starts, goals, (phi @ dmp.weights.T) * x[:, None] * S[:, None, :], dmp.options)
    assert np.abs(raw[:, -1] - goals).max() < 1e-7


def test_goal_equal_to_start_is_finite_and_returns_to_start(rng: np.random.Generator) -> None:
    demo = _demo(rng)
    q = np.array([0.3, -0.2])
    Y = generate(learn_dmp(demo), q, q)
    assert np.all(np.isfinite(Y))
    assert np.array_equal(Y[0], q) and np.array_equal(Y[-1], q)


def test_demo_that_returns_to_its_start_is_learned_without_division_by_zero() -> None:
    t = np.linspace(0.0, 1.0, 301)
    demo = np.stack([0.4 + 0.8 * np.sin(np.pi * t) ** 2, np.full_like(t, -0.3)], axis=1)  # g == y0 in both DOFs
    dmp = learn_dmp(demo)
    assert not dmp.scaled.any()
    assert np.all(np.isfinite(dmp.weights))
    assert np.abs(generate(dmp, demo[0], demo[-1]) - demo).max() < 1e-3
    shifted = generate(dmp, demo[0] + 0.1, demo[-1] + 0.1)  # the excursion is kept, not scaled away
    assert np.ptp(shifted[:, 0]) == pytest.approx(np.ptp(demo[:, 0]), abs=0.05)


def test_scaling_is_used_only_where_the_demo_mostly_moves_start_to_goal() -> None:
    t = np.linspace(0.0, 1.0, 201)
    s = t**3 * (10 - 15 * t + 6 * t**2)
    demo = np.stack([s, 0.05 * s + np.sin(np.pi * t)], axis=1)  # DOF 2: small net motion, big excursion
    dmp = learn_dmp(demo, DMPOptions(min_amplitude_ratio=0.5))
    assert dmp.scaled.tolist() == [True, False]
    assert not learn_dmp(demo, DMPOptions(scaling="none")).scaled.any()


def test_blended_path_starts_at_real_start_and_ends_at_real_goal(rng: np.random.Generator) -> None:
    demo = _demo(rng)
    fwd, rev = learn_dmp(demo), learn_dmp(demo[::-1])
    start, goal = demo[0] + [0.15, -0.2], demo[-1] + [-0.1, 0.25]
    Y = generate_blended(fwd, rev, start, goal)
    assert np.array_equal(Y[0], start) and np.array_equal(Y[-1], goal)
    # at the demo's own endpoints the blend reproduces the demo
    assert np.abs(generate_blended(fwd, rev, demo[0], demo[-1]) - demo).max() < 1e-3


def test_blend_requires_matching_shapes() -> None:
    with pytest.raises(ValueError, match="shapes differ"):
        blend_forward_reverse(np.zeros((10, 2)), np.zeros((11, 2)))


def test_bad_inputs_raise_with_a_message() -> None:
    with pytest.raises(ValueError, match="shape"):
        learn_dmp(np.zeros((2, 2)))
    with pytest.raises(ValueError, match="NaN"):
        learn_dmp(np.full((10, 2), np.nan))
    with pytest.raises(ValueError, match="scaling"):
        DMPOptions(scaling="log")
    with pytest.raises(ValueError, match="settled"):
        learn_dmp(np.linspace(0, 1, 50)[:, None], DMPOptions(alpha_y=5.0))
    dmp = learn_dmp(np.linspace(0, 1, 50)[:, None])
    with pytest.raises(ValueError, match="shape"):
        generate(dmp, np.zeros(2), np.zeros(2))


@pytest.mark.parametrize("options, match", [
    ({"alpha_y": 2000.0}, "diverges"), ({"beta_y": 1e6}, "diverges"),  # explicit Euler blows up to NaN
    ({"alpha_x": 1e3}, "closer than a float resolves"),
])
def test_options_whose_rollout_or_basis_breaks_down_are_refused_not_turned_into_nan(options, match) -> None:
    t = np.linspace(0.0, 1.0, 601)
    demo = np.stack([np.sin(3 * t), t**2], axis=1)
    with np.errstate(over="raise", invalid="raise", divide="raise"):  # and no numpy warning on the way
        with pytest.raises(ValueError, match=match):
            learn_dmp(demo, DMPOptions(**options))


@pytest.mark.parametrize("options, match", [({"alpha_y": "48"}, "alpha_y"), ({"alpha_y": None}, "alpha_y"),
                                            ({"n_basis": 10**12}, "n_basis"), ({"beta_y": -1.0}, "beta_y"),
                                            ({"min_amplitude_ratio": "0.5"}, "min_amplitude_ratio"),
                                            ({"min_amplitude_ratio": True}, "min_amplitude_ratio"),
                                            ({"min_amplitude_ratio": 1.5}, "min_amplitude_ratio")])
def test_bad_option_values_are_value_errors_naming_the_option(options, match) -> None:
    with pytest.raises(ValueError, match=match):
        DMPOptions(**options)


def test_numpy_scalar_options_are_kept_as_plain_numbers_that_a_saved_library_can_write() -> None:
    options = DMPOptions(n_basis=np.int64(300), alpha_y=np.float32(48), beta_y=np.float64(12), alpha_x=np.int32(4),
                         width=np.float32(0.5), min_amplitude_ratio=np.float64(0.5))
    assert json.loads(json.dumps(dataclasses.asdict(options))) == dataclasses.asdict(DMPOptions(
        n_basis=300, alpha_y=48.0, beta_y=12.0, alpha_x=4.0, width=0.5, min_amplitude_ratio=0.5))
    assert all(type(v) in (int, float, str) for v in dataclasses.asdict(options).values())


def test_a_grid_too_large_to_hold_is_refused_before_it_is_allocated() -> None:
    with pytest.raises(ValueError, match="DMP grid of 2001 samples x 10000 basis functions"):
        learn_dmp(np.linspace(0, 1, 2001)[:, None], DMPOptions(n_basis=10_000))


def test_generation_is_closed_form_and_batched(rng: np.random.Generator, monkeypatch) -> None:
    """Generating a path never steps the dynamics (no call of integrate) and a batch equals one call per query."""
    import tpee_ompl.library.dmp as dmp_module

    demo = _demo(rng)
    fwd, rev = learn_dmp(demo), learn_dmp(demo[::-1])
    starts = demo[0] + rng.uniform(-0.2, 0.2, (200, 2))
    goals = demo[-1] + rng.uniform(-0.2, 0.2, (200, 2))

    def no_integration(*args, **kwargs):
        raise AssertionError("generation must not integrate the dynamics")

    monkeypatch.setattr(dmp_module, "integrate", no_integration)
    batch = generate_blended(fwd, rev, starts, goals)
    assert batch.shape == (200, fwd.n_steps, 2) and np.all(np.isfinite(batch))
    for k in (0, 99, 199):
        np.testing.assert_array_equal(batch[k], generate_blended(fwd, rev, starts[k], goals[k]))


def test_a_demo_or_rollout_too_large_for_the_arithmetic_is_refused_not_turned_into_inf() -> None:
    """learn_dmp(demo * 1e200) returned non-finite weights and generate a non-finite path, with a RuntimeWarning only."""
    import warnings

    t = np.linspace(0.0, 1.0, 61)[:, None]
    demo = np.hstack([np.sin(3 * t), t**2])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # and no numpy overflow warning on the way
        with pytest.raises(ValueError, match="overflow"):
            learn_dmp(demo * 1e200)
        dmp = learn_dmp(demo)
        with pytest.raises(ValueError, match="overflow"):
            generate(dmp, np.array([1e308, 0.0]), np.array([-1e308, 1.0]))


def test_a_complex_or_dimensionless_demo_and_complex_ends_are_refused():
    """A complex demo was learned with its imaginary part dropped (a ComplexWarning only); a (P, 0) demo failed in
    numpy's stack ("need at least one array to stack")."""
    import pytest

    from tpee_ompl.library.dmp import generate, learn_dmp

    t = np.linspace(0.0, 1.0, 60)
    with pytest.raises(ValueError, match="demo"):
        learn_dmp(np.c_[t, t] + 1j)
    with pytest.raises(ValueError, match="D >= 1"):
        learn_dmp(np.zeros((60, 0)))
    dmp = learn_dmp(np.c_[t, t])
    with pytest.raises(ValueError, match="start"):
        generate(dmp, np.array([0.0, 0.0]) + 1j, np.array([1.0, 1.0]))


def test_a_demo_shorter_than_the_options_need_is_refused_up_front_naming_demo_and_the_minimum() -> None:
    """learn_dmp took P >= 3 but failed below 50 samples with the defaults, advising a larger alpha_y."""
    from tpee_ompl.library.dmp import min_samples

    assert min_samples() == min_samples(DMPOptions()) == 50
    t = np.linspace(0.0, 1.0, 20)
    with pytest.raises(ValueError, match=r"^demo has 20 samples; .* needs at least 50 .*diverges.*resample") as err:
        learn_dmp(np.c_[t, t**2])
    assert "\n" not in str(err.value) and "increase alpha_y" not in str(err.value)
    t = np.linspace(0.0, 1.0, 50)
    assert learn_dmp(np.c_[t, t**2]).n_steps == 50


@pytest.mark.parametrize("alpha_y", [36.0, 48.0, 56.0, 200.0])
def test_min_samples_is_exactly_where_the_rollout_first_settles(alpha_y: float) -> None:
    from tpee_ompl.library.dmp import DMP, min_samples

    options = DMPOptions(alpha_y=alpha_y)
    need = min_samples(options)
    DMP.from_weights(np.zeros((1, options.basis_count(need))), [0.0], [1.0], [True], need, options)
    with pytest.raises(ValueError, match=f"use at least {need} samples"):
        DMP.from_weights(np.zeros((1, options.basis_count(need - 1))), [0.0], [1.0], [True], need - 1, options)


def test_the_unsettled_error_advises_what_fixes_it_more_samples_not_a_larger_alpha_y() -> None:
    """The old advice, "increase alpha_y", made a coarse grid's unstable rollout worse; more samples fix it."""
    from tpee_ompl.library.dmp import DMP

    def fails(n_steps: int, options: DMPOptions) -> bool:
        try:
            DMP.from_weights(np.zeros((1, options.basis_count(n_steps))), [0.0], [1.0], [True], n_steps, options)
        except ValueError:
            return True
        return False

    with pytest.raises(ValueError, match="diverges on 20 samples: use at least 50 samples") as err:
        DMP.from_weights(np.zeros((1, 9)), [0.0], [1.0], [True], 20, DMPOptions())
    assert "alpha_y or" not in str(err.value)
    assert all(fails(20, DMPOptions(alpha_y=a)) for a in (48.0, 96.0, 480.0))  # a larger alpha_y does not help
    assert not fails(50, DMPOptions())  # the advice does
    with pytest.raises(ValueError, match="increase alpha_y"):  # too soft for any grid: then alpha_y is the fix
        DMP.from_weights(np.zeros((1, 24)), [0.0], [1.0], [True], 50, DMPOptions(alpha_y=5.0))


def _blend_pair() -> tuple:
    t = np.linspace(0.0, 1.0, 60)
    demo = np.stack([np.sin(np.pi * t), t**2], axis=1)
    return learn_dmp(demo), learn_dmp(demo[::-1])


@pytest.mark.parametrize("start, goal, match", [
    (np.array([1j, 0.0]), [1.0, 1.0], "start must be real numbers"),  # was cast with a ComplexWarning only
    ([0.0, 0.0], [1.0, 1.0j], "goal must be real numbers"),
    ([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], r"start and goal must have shape \(2,\) or \(B, 2\)"),  # numpy's broadcast
    (np.zeros((3, 2)), np.ones((4, 2)), r"start and goal batches differ: shapes \(3, 2\) and \(4, 2\)"),
])
def test_generate_blended_checks_start_and_goal_as_generate_does_naming_them(start, goal, match: str) -> None:
    forward, reverse = _blend_pair()
    with pytest.raises(ValueError, match=match):
        generate_blended(forward, reverse, start, goal)


def test_generate_blended_takes_one_start_with_a_batch_of_goals_as_generate_does() -> None:
    """A (D,) start with (B, D) goals failed with "forward and reverse shapes differ"."""
    forward, reverse = _blend_pair()
    goals = np.array([[1.0, 1.0], [0.5, -0.5], [0.0, 2.0]])
    out = generate_blended(forward, reverse, [0.0, 0.0], goals)
    assert out.shape == (3, 60, 2)
    for b, g in enumerate(goals):
        assert np.array_equal(out[b], generate_blended(forward, reverse, [0.0, 0.0], g))


@pytest.mark.parametrize("name", ["forward", "reverse"])
def test_generate_blended_names_an_argument_that_is_no_dmp(name: str) -> None:
    """A non-DMP was an AttributeError ("'str' object has no attribute 'n_steps'")."""
    forward, reverse = _blend_pair()
    args = {"forward": forward, "reverse": reverse, name: "dmp"}
    with pytest.raises(ValueError, match=f"^{name} must be a DMP, got str"):
        generate_blended(args["forward"], args["reverse"], [0.0, 0.0], [1.0, 1.0])
    with pytest.raises(ValueError, match="^dmp must be a DMP, got NoneType"):
        generate(None, [0.0, 0.0], [1.0, 1.0])


@pytest.mark.parametrize("options", ["x", {"alpha_y": 48.0}, 5])
def test_learn_dmp_names_options_that_are_no_dmp_options(options) -> None:
    """learn_dmp(demo, "x") was an AttributeError ("'str' object has no attribute 'alpha_y'")."""
    with pytest.raises(ValueError, match="^options must be a DMPOptions, got "):
        learn_dmp(np.zeros((60, 2)), options)
