"""Discrete dynamic movement primitives (DMPs), paper section 4.2, eqs. 12-17.

Pure numpy functions; a :class:`DMP` is a frozen record of learned weights plus the two response
profiles that make generation a closed form.  Time is the paper's *fake time*, normalised so a
whole path lasts 1 (tau = 1, dimensionless); positions are joint angles in radians.

Model (see ``docs/dmp.md`` for the derivation and every deviation from the printed equations)::

    canonical system (15)   x(t) = exp(-alpha_x t)                      (exact solution, tau = 1)
    basis (14)              psi_i(x) = exp(-h_i (x - c_i)^2)
    forcing (13)            f(x) = sum_i psi_i w_i / sum_i psi_i * x * S
    transformation (12)     y'' = alpha_y (beta_y (g - y) - y') + f(x)

with ``S = g - y0`` (eq. 13, "amplitude" scaling) for DOFs whose demonstration really moves from
start to goal, and ``S = 1`` (absolute forcing, Hoffmann et al. 2009 / Ijspeert et al. 2013 sec. 3.3)
for DOFs whose demonstration returns near its start, where eq. 13 would divide by ~0 in learning
(eq. 16) and amplify the demo's excursion without bound in generation.

The transformation system is integrated by semi-implicit Euler on the demonstration's own grid, and
eq. 16 is inverted *for that integrator*, so a perfect fit of f reproduces the samples exactly;
the only reproduction error left is the locally weighted regression (eq. 17).  The system is
linear in (y0, g) for fixed weights, so every rollout is::

    y(t) = g + (y0 - g) a(t) + S r(t)

where a is the spring-damper's free response and r the response to the learned forcing with S = 1;
both are computed once at learning time by :func:`integrate`, and :func:`generate` is three array
operations (well under a millisecond for hundreds of start/goal pairs).  One linear equality
added to the regression makes the demo's rollout end exactly at its goal, which for scaled DOFs
makes *every* rollout end exactly at its goal (see :func:`learn_dmp` and :func:`generate`).

References
----------
Zou et al., Electronics 2022, 11, 1615, eqs. 12-17.
Ijspeert, Nakanishi, Hoffmann, Pastor, Schaal (2013), Neural Computation 25(2), 328-373.
Hoffmann, Pastor, Park, Schaal (2009), ICRA, "Biologically-inspired dynamical systems for movement
generation: automatic real-time goal adaptation and obstacle avoidance".
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

from ..validation import as_float_array, check_int, check_number, check_type

__all__ = [
    "DMP",
    "DMPOptions",
    "basis_functions",
    "blend_forward_reverse",
    "blend_weight",
    "canonical_phase",
    "generate",
    "generate_blended",
    "integrate",
    "learn_dmp",
    "min_samples",
]

MAX_N_BASIS = 10_000
"""Most basis functions a DMP may have (eq. 14)."""
MAX_GRID_ENTRIES = 20_000_000
"""Most numbers in one DMP grid's basis matrix (samples x basis functions; 160 MB): a larger one is refused,
not allocated (a library file asking for 60001 x 30000 would take 13 GiB).  The packaged library: 601 x 300."""
_MAX_FREE_RESPONSE_AT_END = 1e-6
"""Largest allowed a(T): the spring-damper must have settled by the end of the path."""
MAX_SETTLE_SEARCH = 20_000
"""Most samples :func:`min_samples` tries (a grid of more is refused anyway with the default basis count)."""


@dataclass(frozen=True)
class DMPOptions:
    """Parameters of the DMP (eqs. 12-15); all dimensionless (fake time normalised to 1).

    Attributes
    ----------
    n_basis : int or None
        N, number of Gaussian basis functions (eq. 14). ``None``: half the number of samples,
        which the LWR fit needs to reproduce a 7-step demo within 1e-3 rad (docs/dmp.md).
    alpha_y, beta_y : float
        Spring-damper gains of eq. 12; ``beta_y=None`` means alpha_y / 4 (critical damping).
        alpha_y is large so the free response has died out by t = 1 (exact end, docs/dmp.md).
    alpha_x : float
        Decay rate of the canonical system, eq. 15.
    width : float
        Standard deviation sigma_i of each basis (eq. 14) as a fraction of the spacing of the
        centres in phase.
    scaling : {"amplitude", "none"}
        "amplitude": eq. 13's factor (g - y0) where well defined (see ``min_amplitude_ratio``);
        "none": absolute forcing for every DOF.
    min_amplitude_ratio : float
        A DOF uses eq. 13's scaling only if its demo's |g - y0| is at least this fraction of the
        demo's range (max - min); this bounds the scaled shape by 1 / ratio times |g - y0|.
    """

    n_basis: int | None = None
    alpha_y: float = 48.0
    beta_y: float | None = None
    alpha_x: float = 4.0
    width: float = 0.5
    scaling: str = "amplitude"
    min_amplitude_ratio: float = 0.5

    def __post_init__(self) -> None:
        # the checked values are kept as plain ints and floats: numpy scalars would fail as JSON in a saved library
        set_ = lambda field_, value: object.__setattr__(self, field_, value)  # noqa: E731 (frozen dataclass)
        set_("n_basis", check_int("n_basis", self.n_basis, minimum=2, maximum=MAX_N_BASIS, optional=True))
        for name in ("alpha_y", "alpha_x", "width"):
            set_(name, check_number(name, getattr(self, name), low=0.0, low_open=True))
        set_("beta_y", check_number("beta_y", self.beta_y, low=0.0, low_open=True, optional=True))
        if self.scaling not in ("amplitude", "none"):
            raise ValueError(f"scaling must be 'amplitude' or 'none', got {self.scaling!r}")
        set_("min_amplitude_ratio", check_number("min_amplitude_ratio", self.min_amplitude_ratio, low=0.0,
                                                 low_open=True, high=1.0))

    @property
    def beta(self) -> float:
        """beta_y, defaulting to critical damping alpha_y / 4."""
        return self.alpha_y / 4.0 if self.beta_y is None else float(self.beta_y)

    def basis_count(self, n_steps: int) -> int:
        """N for a demonstration of ``n_steps`` samples."""
        return int(self.n_basis) if self.n_basis is not None else max(2, (n_steps - 1) // 2)


@dataclass(frozen=True, eq=False)
class DMP:
    """A learned multi-DOF DMP on a fixed grid of ``n_steps`` samples over fake time [0, 1].

    Attributes
    ----------
    weights : ndarray, shape (D, N)
        w_i of eq. 13 per DOF.
    start, goal : ndarray, shape (D,), radians
        The demonstration's y0 and g.
    scaled : ndarray of bool, shape (D,)
        True where the forcing is scaled by (g - y0) (eq. 13), False where it is absolute.
    options : DMPOptions
    free_response : ndarray, shape (P,)
        a(t): rollout of eq. 12 from y0 = 1 to g = 0 without forcing.
    forcing_response : ndarray, shape (P, D)
        r(t): rollout from y0 = g = 0 with the learned forcing at S = 1.
    """

    weights: np.ndarray
    start: np.ndarray
    goal: np.ndarray
    scaled: np.ndarray
    options: DMPOptions
    free_response: np.ndarray = field(repr=False)
    forcing_response: np.ndarray = field(repr=False)

    @property
    def n_steps(self) -> int:
        """P, number of samples of every generated path."""
        return int(self.free_response.shape[0])

    @property
    def n_dims(self) -> int:
        """D, number of DOFs."""
        return int(self.weights.shape[0])

    @classmethod
    def from_weights(
        cls,
        weights: np.ndarray,
        start: np.ndarray,
        goal: np.ndarray,
        scaled: np.ndarray,
        n_steps: int,
        options: DMPOptions | None = None,
    ) -> DMP:
        """Rebuild a DMP from stored parameters (recomputes the response profiles)."""
        options = DMPOptions() if options is None else check_type("options", options, DMPOptions)
        weights = np.atleast_2d(np.asarray(weights, dtype=float))
        start, goal = np.asarray(start, dtype=float).ravel(), np.asarray(goal, dtype=float).ravel()
        scaled = np.asarray(scaled, dtype=bool).ravel()
        D, N = weights.shape
        if start.shape != (D,) or goal.shape != (D,) or scaled.shape != (D,):
            raise ValueError(f"start, goal and scaled must have shape ({D},) to match weights {weights.shape}")
        if N != options.basis_count(n_steps):
            raise ValueError(f"weights have {N} basis functions; options give {options.basis_count(n_steps)}")
        x, phi, free, impulse = _grid(n_steps, options)
        f = (phi @ weights.T) * x[:, None]
        # integrate(0, 0, f) is linear and time-invariant in f: its impulse response convolved with f
        forcing = np.stack([np.convolve(f[:, d], impulse)[:n_steps] for d in range(D)], axis=1)
        return cls(weights, start, goal, scaled, options, free, forcing)


@functools.lru_cache(maxsize=8)
def _grid(n_steps: int, options: DMPOptions) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """What every DMP on one grid shares: phase (P,), normalised basis (P, N), free response (P,), and the
    impulse response (P,) of eq. 12's rollout from rest at 0 towards 0 to a unit forcing at step 0.

    Loading a library rebuilds hundreds of DMPs on one grid; with these a rebuild is a convolution
    instead of a rollout loop.  The arrays are read-only (shared by the cache).
    """
    n_basis = options.basis_count(n_steps)
    if n_steps * n_basis > MAX_GRID_ENTRIES:
        raise ValueError(f"a DMP grid of {n_steps} samples x {n_basis} basis functions is more than {MAX_GRID_ENTRIES:.0e} "
                         "numbers: fewer samples or basis functions")
    x = canonical_phase(n_steps, options.alpha_x)
    phi = basis_functions(x, n_basis, options.alpha_x, options.width, normalized=True)
    free = _free_response(n_steps, options)
    unit = np.zeros((n_steps, 1))
    unit[0] = 1.0
    impulse = integrate(np.zeros(1), np.zeros(1), unit, options)[:, 0]
    for a in (x, phi, free, impulse):
        a.setflags(write=False)
    return x, phi, free, impulse


def canonical_phase(n_steps: int, alpha_x: float) -> np.ndarray:
    """Phase x at the P samples of fake time [0, 1]: exact solution of eq. 15 with tau = 1, shape (P,)."""
    if n_steps < 3:
        raise ValueError(f"need at least 3 samples, got {n_steps}")
    return np.exp(-alpha_x * np.linspace(0.0, 1.0, n_steps))


def basis_functions(x: np.ndarray, n_basis: int, alpha_x: float, width: float = 0.5, normalized: bool = False) -> np.ndarray:
    """Gaussian basis functions of eq. 14 at phases x, shape (len(x), N).

    Centres c_i are spaced evenly in time (c_i = exp(-alpha_x i / (N - 1))); sigma_i is ``width``
    times the gap to the next centre.  ``normalized`` divides each row by its sum (eq. 13's ratio).
    """
    c = np.exp(-alpha_x * np.linspace(0.0, 1.0, n_basis))
    gap = np.abs(np.diff(c))
    gap = np.append(gap, gap[-1])
    with np.errstate(divide="ignore", over="ignore"):
        h = 1.0 / (2.0 * (width * gap) ** 2)
    if not np.isfinite(h).all():  # the last centres coincide in floating point: no basis can tell them apart
        raise ValueError(f"alpha_x = {alpha_x:g} with {n_basis} basis functions puts centres closer than a float "
                         "resolves (width * gap underflows): lower alpha_x, width or the number of basis functions")
    psi = np.exp(-h * (np.asarray(x, dtype=float)[:, None] - c) ** 2)
    if normalized:
        psi = psi / np.maximum(psi.sum(axis=1, keepdims=True), np.finfo(float).tiny)
    return psi


def integrate(y0: np.ndarray, g: np.ndarray, forcing: np.ndarray, options: DMPOptions | None = None) -> np.ndarray:
    """Roll out eq. 12 by semi-implicit Euler on the grid of ``forcing``; batched over leading axes.

    Parameters
    ----------
    y0, g : ndarray, shape (..., D), radians
        Start (with zero initial velocity) and goal.
    forcing : ndarray, shape (..., P, D)
        f at each sample (broadcast against y0/g); the step k -> k+1 uses f[k].

    Returns
    -------
    ndarray, shape (..., P, D): the positions y at the P samples, dt = 1 / (P - 1).

    This is the reference rollout; :func:`generate` evaluates the same recursion in closed form.
    The loop runs over time only (P - 1 steps); each step is vectorised over batch and DOFs.
    """
    options = options or DMPOptions()
    forcing = np.asarray(forcing, dtype=float)
    y0, g = np.asarray(y0, dtype=float), np.asarray(g, dtype=float)
    P = forcing.shape[-2]
    shape = np.broadcast_shapes(y0.shape, g.shape, forcing.shape[:-2] + forcing.shape[-1:])
    dt = 1.0 / (P - 1)
    ay, by = options.alpha_y, options.beta
    out = np.empty(shape[:-1] + (P, shape[-1]))
    y = np.broadcast_to(y0, shape).astype(float)
    v = np.zeros(shape)
    out[..., 0, :] = y
    for k in range(P - 1):
        acc = ay * (by * (g - y) - v) + forcing[..., k, :]
        v = v + dt * acc
        y = y + dt * v
        out[..., k + 1, :] = y
    return out


def _free_response(n_steps: int, options: DMPOptions) -> np.ndarray:
    a = _free_rollout(n_steps, options)
    if not np.isfinite(a).all() or abs(a[-1]) > _MAX_FREE_RESPONSE_AT_END:
        raise ValueError(f"{_gains(options)}: {_failure(a[-1])} on {n_steps} samples{_settle_advice(n_steps, options)}")
    return a


def _free_rollout(n_steps: int, options: DMPOptions) -> np.ndarray:
    """a(t), shape (P,): eq. 12 rolled out by :func:`integrate` from y0 = 1 to g = 0 without forcing."""
    with np.errstate(over="ignore", invalid="ignore"):  # a stiff spring-damper diverges: said by the callers
        return integrate(np.ones(1), np.zeros(1), np.zeros((n_steps, 1)), options)[:, 0]


def _gains(options: DMPOptions) -> str:
    return f"the spring-damper (alpha_y = {options.alpha_y:g}, beta_y = {options.beta:g})"


def _failure(end: float) -> str:
    """What is wrong with a free response ending at ``end`` = a(T): it diverges (grew past its start) or it has not
    settled."""
    if not np.isfinite(end) or abs(end) > 1.0:
        return "its semi-implicit Euler rollout diverges"
    return f"it has not settled by the end of the path (a(T) = {end:.1e} > {_MAX_FREE_RESPONSE_AT_END:g})"


def _settle_advice(n_steps: int, options: DMPOptions) -> str:
    """The fix that works: more samples (a smaller step dt), or a stiffer spring when no number of samples settles."""
    need = min_samples(options)
    if need is None:
        if _failure(_free_rollout(MAX_SETTLE_SEARCH, options)[-1]).endswith("diverges"):  # too stiff for any grid
            return f": lower alpha_y or beta_y (no grid of up to {MAX_SETTLE_SEARCH} samples is fine enough for them)"
        return f": increase alpha_y (it is still moving at t = 1, on any grid of up to {MAX_SETTLE_SEARCH} samples)"
    if n_steps < need:
        return f": use at least {need} samples (a smaller step dt = 1 / (P - 1))"
    return f": change alpha_y or beta_y (these gains settle on {need} samples but not on {n_steps})"


@functools.lru_cache(maxsize=32)
def min_samples(options: DMPOptions | None = None) -> int | None:
    """Fewest samples P a demonstration needs with ``options``: the smallest grid (dt = 1 / (P - 1)) on which the
    spring-damper of eq. 12, rolled out by :func:`integrate` from y0 = 1 to g = 0 without forcing, has settled by
    the end of the path (|a(T)| <= 1e-6); None if no P up to :data:`MAX_SETTLE_SEARCH` does (alpha_y too small).

    50 with the defaults (alpha_y = 48, beta_y = 12): on fewer than 30 samples the semi-implicit Euler step is
    unstable (4 - 2 dt alpha_y - dt^2 alpha_y beta_y <= 0) and the rollout diverges; on 30-49 it has not settled.
    The search replays :func:`integrate`'s arithmetic for every P at once, so the answer agrees with it exactly.
    """
    options = options or DMPOptions()
    ay, by = options.alpha_y, options.beta
    for lo, hi in ((3, 256), (256, 2048), (2048, MAX_SETTLE_SEARCH + 1)):
        P = np.arange(lo, hi)
        dt = 1.0 / (P - 1)
        y, v, end = np.ones(len(P)), np.zeros(len(P)), np.empty(len(P))
        with np.errstate(over="ignore", invalid="ignore"):
            for k in range(hi - 2):  # the same operations as integrate's loop, g = 0 and no forcing
                acc = ay * (by * (0.0 - y) - v) + 0.0
                v = v + dt * acc
                y = y + dt * v
                if k + 2 >= lo:
                    end[k + 2 - lo] = y[k + 2 - lo]  # P = k + 2 samples end after step k
        settled = np.isfinite(end) & (np.abs(end) <= _MAX_FREE_RESPONSE_AT_END)
        if settled.any():
            return int(P[np.argmax(settled)])
    return None


def learn_dmp(demo: np.ndarray, options: DMPOptions | None = None) -> DMP:
    """Learn a DMP from one demonstration by locally weighted regression (eqs. 16-17).

    Parameters
    ----------
    demo : ndarray, shape (P, D), radians
        Samples evenly spaced in fake time over [0, 1], P >= :func:`min_samples` (50 with the default options;
        resample a shorter demo more finely, e.g. :func:`tpee_ompl.planning.paths.resample_waypoints`).
    options : DMPOptions, optional

    Steps: (i) the target forcing of eq. 16, inverted for the semi-implicit Euler step of
    :func:`integrate` with zero initial velocity; (ii) per basis, the weighted least-squares weight
    of eq. 17, w_i = sum_t psi_i zeta f_target / sum_t psi_i zeta^2 with zeta = x S; (iii) the
    minimum-norm change of w that makes the rollout of the demo end exactly at its goal (one
    linear equality per DOF: r(T) = a(T) S_demo / S); (iv) the response profiles.
    """
    options = DMPOptions() if options is None else check_type("options", options, DMPOptions)
    demo = as_float_array(demo, "demo")  # a complex demo lost its imaginary part with a warning
    if demo.ndim == 1:
        demo = demo[:, None]
    if demo.ndim != 2 or demo.shape[0] < 3 or demo.shape[1] < 1:
        raise ValueError(f"demo must have shape (P >= 3, D >= 1); got {demo.shape}")
    if not np.all(np.isfinite(demo)):
        raise ValueError("demo contains NaN or inf")
    P, D = demo.shape
    need = min_samples(options)
    if need is not None and P < need:  # before any work: the rollout on this grid cannot end at the goal
        raise ValueError(f"demo has {P} samples; {_gains(options)} needs at least {need} (on {P} "
                         f"{_failure(_free_rollout(P, options)[-1])}): resample the demo more finely")
    N = options.basis_count(P)
    dt = 1.0 / (P - 1)
    ay, by = options.alpha_y, options.beta
    y0, g = demo[0], demo[-1]
    amplitude = g - y0
    span = np.ptp(demo, axis=0)
    scaled = (options.scaling == "amplitude") & (np.abs(amplitude) > 0) & (
        np.abs(amplitude) >= options.min_amplitude_ratio * span
    )
    S = np.where(scaled, amplitude, 1.0)

    with np.errstate(over="ignore", invalid="ignore"):  # a demo too large for the arithmetic is refused below
        # (i) eq. 16 numerator for the discrete step: v[k+1] = v[k] + dt acc[k], y[k+1] = y[k] + dt v[k+1]
        v = np.vstack([np.zeros((1, D)), np.diff(demo, axis=0) / dt])
        acc = np.diff(v, axis=0) / dt
        f_target = acc - ay * (by * (g - demo[:-1]) - v[:-1])  # (P-1, D)

        # (ii) LWR, eq. 17 (the grid's phase, normalised basis, free and impulse responses: shared, cached)
        x, phi, free, response = _grid(P, options)
        psi = basis_functions(x, N, options.alpha_x, options.width)
        zeta = x[:-1, None] * S  # (P-1, D)
        num = psi[:-1].T @ (zeta * f_target)
        den = psi[:-1].T @ (zeta**2)
        weights = (num / np.maximum(den, np.finfo(float).tiny)).T  # (D, N)

        # (iii) exact end: response at T of each unit basis forcing x phi_i (S = 1) is linear in w; by time
        # invariance, y(T) after a unit impulse at step k is the impulse response at step P-1-k
        c = (response[:0:-1] * x[:-1]) @ phi[:-1]  # (N,)
        target = free[-1] * amplitude / S  # scaled: a(T); absolute: a(T) (g - y0)
        weights = weights + np.outer(target - weights @ c, c) / (c @ c)
    if not np.all(np.isfinite(weights)):
        raise ValueError(f"demo values up to {np.max(np.abs(demo)):.3g} overflow the DMP's arithmetic")
    return DMP.from_weights(weights, y0.copy(), g.copy(), scaled, P, options)  # what loading a library does too


def generate(dmp: DMP, start: np.ndarray, goal: np.ndarray) -> np.ndarray:
    """Rollout of a learned DMP from ``start`` to ``goal`` in closed form, shape (..., P, D).

    ``start`` and ``goal`` have shape (D,) or (B, D) (a batch).  Equals :func:`integrate` with the
    learned forcing to rounding error.  The first sample is ``start`` and the last ``goal``
    bit-for-bit: both are assigned, which moves them by rounding error only for scaled DOFs and by
    at most a(T) |g - y0 - (g_demo - y0_demo)| (< 1e-8 rad with the defaults) for absolute ones.
    goal == start is well defined: scaled DOFs stay put (eq. 13's forcing vanishes), absolute DOFs
    replay the demo's excursion and return.
    """
    start, goal = _ends(check_type("dmp", dmp, DMP).n_dims, start, goal)
    with np.errstate(over="ignore", invalid="ignore"):  # refused below
        S = np.where(dmp.scaled, goal - start, 1.0)
        y = (
            goal[..., None, :]
            + (start - goal)[..., None, :] * dmp.free_response[:, None]
            + S[..., None, :] * dmp.forcing_response
        )
    if not np.all(np.isfinite(y)):
        raise ValueError("start and goal overflow the rollout's arithmetic")
    y[..., 0, :] = start
    y[..., -1, :] = goal
    return y


@functools.lru_cache(maxsize=16)
def blend_weight(n_steps: int) -> np.ndarray:
    """Weight of the forward rollout at each sample: 1 - quintic smoothstep of fake time, shape (P,) (read-only:
    cached, every query of a library asks for the same).

    1 at the start, 0 at the end, zero slope at both ends, so the blend leaves the real start
    along the forward DMP and reaches the real goal along the reverse one (section 4.2.3).
    """
    u = np.linspace(0.0, 1.0, n_steps)
    w = 1.0 - u**3 * (10.0 - 15.0 * u + 6.0 * u**2)
    w.setflags(write=False)
    return w


def blend_forward_reverse(forward: np.ndarray, reverse: np.ndarray) -> np.ndarray:
    """Blend a forward rollout with a reverse rollout (given in its own time), shape (..., P, D).

    ``reverse`` runs from the real goal to the demo start; it is flipped in time and mixed with
    weight 1 - w (:func:`blend_weight`), so the result starts at forward[0] and ends at reverse[0]
    exactly.
    """
    forward, reverse = np.asarray(forward, dtype=float), np.asarray(reverse, dtype=float)
    if forward.shape != reverse.shape:
        raise ValueError(f"forward and reverse shapes differ: {forward.shape} vs {reverse.shape}")
    w = blend_weight(forward.shape[-2])[:, None]
    out = w * forward + (1.0 - w) * np.flip(reverse, axis=-2)
    out[..., 0, :] = forward[..., 0, :]
    out[..., -1, :] = reverse[..., 0, :]
    return out


def generate_blended(forward: DMP, reverse: DMP, start: np.ndarray, goal: np.ndarray) -> np.ndarray:
    """Section 4.2.3 steps 2-3: forward DMP start -> demo goal, reverse DMP goal -> demo start, blended.

    ``forward`` was learned from the demo, ``reverse`` from the demo flipped in time (so
    ``reverse.goal`` is the demo start).  ``start`` and ``goal`` are checked as by :func:`generate` (shape (D,)
    or (B, D), finite real numbers; one of shape (D,) goes with every row of a batch).  Returns shape (..., P, D)
    from ``start`` to ``goal``.
    """
    check_type("forward", forward, DMP), check_type("reverse", reverse, DMP)
    if forward.n_steps != reverse.n_steps or forward.n_dims != reverse.n_dims:
        raise ValueError("forward and reverse DMPs must share n_steps and n_dims")
    start, goal = _ends(forward.n_dims, start, goal)
    try:
        shape = np.broadcast_shapes(start.shape, goal.shape)
    except ValueError:
        raise ValueError(f"start and goal batches differ: shapes {start.shape} and {goal.shape}") from None
    start, goal = np.broadcast_to(start, shape), np.broadcast_to(goal, shape)
    fwd = generate(forward, start, np.broadcast_to(forward.goal, shape))
    rev = generate(reverse, goal, np.broadcast_to(reverse.goal, shape))
    return blend_forward_reverse(fwd, rev)


def _ends(n_dims: int, start: object, goal: object) -> tuple[np.ndarray, np.ndarray]:
    """``start`` and ``goal`` as float arrays of shape (D,) or (B, D) of finite real numbers, else ValueError."""
    start, goal = as_float_array(start, "start"), as_float_array(goal, "goal")
    if start.shape[-1:] != (n_dims,) or goal.shape[-1:] != (n_dims,) or start.ndim > 2 or goal.ndim > 2:
        raise ValueError(f"start and goal must have shape ({n_dims},) or (B, {n_dims}); got {start.shape}, {goal.shape}")
    if not (np.all(np.isfinite(start)) and np.all(np.isfinite(goal))):
        raise ValueError("start or goal contains NaN or inf")
    return start, goal
