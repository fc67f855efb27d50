"""How a path library is built: its settings (:class:`LibraryBuildOptions`), demos collected per pair
(in parallel with the default sampler and planner), and the forward/reverse DMPs learned from them.

:meth:`tpee_ompl.library.path_library.PathLibrary.build` and ``build_default`` call these; the
``tpee-ompl library build`` command takes its defaults from :class:`LibraryBuildOptions`.

Resampling: each straight segment between consecutive fake-time steps gets ``per_step`` samples
with a quintic time scaling (zero velocity and acceleration at every step), applied to all four
DOFs alike, so the resampled demo is *geometrically identical* to the planned (checked) path and
smooth in fake time, which the DMP needs to reproduce it within 1e-3 rad (docs/dmp.md).
"""

from __future__ import annotations

import contextlib
import logging
import os
import signal
import sys
from collections import Counter, deque
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass
from multiprocessing import get_context
from multiprocessing.connection import Connection, wait
from multiprocessing.process import BaseProcess
from typing import Any

import numpy as np

from ..signals import child_sigint, die_with_parent, exit_reason, sigint_blocked_for_children
from ..model.sectors import SECTOR_PAIRS, check_sector
from ..model.wearer_arm import WearerArm
from ..planning.paths import resample_waypoints
from ..validation import check_bool, check_int, check_number, resolve_options
from .demos import (
    DEMO_MARGINS,
    MAX_PER_STEP,
    N_FAKE_TIME_STEPS,
    POINTING_LINKS,
    DemoPlanner,
    PairDemos,
    check_demo_margins,
    collect_pair,
    query_sampler,
)
from .dmp import DMPOptions, learn_dmp, min_samples

__all__ = ["LIBRARY_DMP_OPTIONS", "LibraryBuildOptions", "collect_default_demos", "default_build_params", "learn_demos"]

log = logging.getLogger(__name__)

LIBRARY_DMP_OPTIONS = DMPOptions(scaling="none")
"""DMP options of the library's DOF3/DOF4 primitives: absolute forcing instead of eq. 13's (g - y0)
scaling, which flips or shrinks a demo's detour whenever the query moves pan or tilt the other way
or less far than the demo (docs/dmp.md has the measurements)."""

Collected = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, Counter]
"""What :func:`~tpee_ompl.library.demos.collect_pair` returns: starts, goals, waypoints, margins, counters."""


@dataclass(frozen=True)
class LibraryBuildOptions:
    """Settings of a library build, checked once here (defaults: those of the packaged library).

    Attributes
    ----------
    per_pair : int
        Demonstrations per ordered sector pair (at most; fewer if draws run out). Default 20.
    seed : int >= 0
        Seed of the draws (one child generator per pair) and of the default planner.
    pairs : sequence of (from, to) sector pairs
        Ordered cross-sector pairs to build (default all 12, :data:`~tpee_ompl.model.sectors.SECTOR_PAIRS`).
    min_difference : float >= 0, radians
        A draw is kept only if its DOF3/DOF4 (start, goal) 4-vector is this far (Euclidean) from
        every stored one of its pair. Default 0.15.
    max_attempts : int >= 1, optional
        Draws per pair before giving up on ``per_pair``; None: 3 x ``per_pair`` (planning-necessary
        draws of the shoulder pairs 3 <-> 4 cost seconds each and cluster within ~0.3 rad).
    per_step : int
        Samples per fake-time step of the resampled demos the DMPs learn (default 100): at least the number that
        gives the DMPs :func:`~tpee_ompl.library.dmp.min_samples` samples (6 per_step + 1; 9 with the default
        ``dmp_options``).
    max_samples : int >= 1
        Dimension-RRT samples per demonstration (default planner only). Default 2500.
    timeout : float > 0, seconds
        Dimension-RRT wall-clock limit per demonstration (default planner only). Default 10.
    require_planning : bool
        Default sampler only: keep only draws whose straight motion collides. Default True.
    demo_margins : sequence of float in [0, 1], metres
        Margins around the pointing links tried, widest first, before the robot's own when
        planning a demonstration (default planner only; :data:`~tpee_ompl.library.demos.DEMO_MARGINS`).
    workers : int >= 1
        Processes building the pairs in parallel (default sampler and planner only). Default 1.
    dmp_options : DMPOptions
        The DMPs' settings (default :data:`LIBRARY_DMP_OPTIONS`).
    progress : bool
        A progress bar on stderr (pairs done, with an estimate of the time left; default sampler and planner
        only; ``tpee-ompl library build`` shows it unless ``--no-progress``).  Not a build parameter: the library
        is the same either way.  Default False.
    """

    per_pair: int = 20
    seed: int = 0
    pairs: Sequence[tuple[int, int]] = SECTOR_PAIRS
    min_difference: float = 0.15
    max_attempts: int | None = None
    per_step: int = 100
    max_samples: int = 2500
    timeout: float = 10.0
    require_planning: bool = True
    demo_margins: Sequence[float] = DEMO_MARGINS
    workers: int = 1
    dmp_options: DMPOptions = LIBRARY_DMP_OPTIONS
    progress: bool = False

    def __post_init__(self) -> None:
        set_ = lambda field_, value: object.__setattr__(self, field_, value)  # noqa: E731 (frozen dataclass)
        set_("per_pair", check_int("per_pair", self.per_pair, minimum=1))
        set_("seed", check_int("seed", self.seed, minimum=0))
        set_("pairs", _check_pairs(self.pairs))
        set_("min_difference", check_number("min_difference", self.min_difference, low=0.0))
        set_("max_attempts", check_int("max_attempts", self.max_attempts, minimum=1, optional=True))
        set_("per_step", check_int("per_step", self.per_step, minimum=1, maximum=MAX_PER_STEP))
        set_("max_samples", check_int("max_samples", self.max_samples, minimum=1))
        set_("timeout", check_number("timeout", self.timeout, low=0.0, low_open=True))
        set_("require_planning", check_bool("require_planning", self.require_planning))
        set_("demo_margins", check_demo_margins(self.demo_margins))
        set_("workers", check_int("workers", self.workers, minimum=1))
        set_("progress", check_bool("progress", self.progress))
        if not isinstance(self.dmp_options, DMPOptions):
            raise ValueError(f"dmp_options must be a DMPOptions, got {self.dmp_options!r}")
        _check_dmp_grid(self.per_step, self.dmp_options)

    @property
    def draws_per_pair(self) -> int:
        """``max_attempts``, or 3 x ``per_pair`` when it is None."""
        return self.max_attempts if self.max_attempts is not None else 3 * self.per_pair

    @classmethod
    def resolve(cls, options: LibraryBuildOptions | None, overrides: Mapping[str, Any]) -> LibraryBuildOptions:
        """``options`` (defaults if None) with keyword overrides applied; an unknown name raises TypeError."""
        return resolve_options(cls, options, overrides)


def _check_dmp_grid(per_step: int, options: DMPOptions) -> None:
    """The DMPs' grid of 6 ``per_step`` + 1 samples is fine enough for ``options`` (:func:`min_samples`); ValueError
    naming ``per_step`` and the smallest value that works (a build would otherwise fail after all its planning)."""
    need = min_samples(options)
    gains = f"alpha_y = {options.alpha_y:g}, beta_y = {options.beta:g}"
    if need is None:
        raise ValueError(f"dmp_options: the spring-damper ({gains}) settles on no grid of DMP samples; change alpha_y")
    steps = N_FAKE_TIME_STEPS - 1
    if steps * per_step + 1 < need:
        smallest = -(-(need - 1) // steps)
        if smallest > MAX_PER_STEP:
            raise ValueError(f"dmp_options: the spring-damper ({gains}) needs DMPs of {need} samples, more than "
                             f"per_step {MAX_PER_STEP} gives; change alpha_y")
        raise ValueError(f"per_step {per_step} gives DMPs of {steps * per_step + 1} samples; with dmp_options {gains} "
                         f"they need at least {need}: per_step must be at least {smallest}")


def _check_pairs(pairs: Sequence[tuple[int, int]]) -> tuple[tuple[int, int], ...]:
    try:
        out = tuple((check_sector(i), check_sector(j)) for i, j in pairs)
    except TypeError:
        raise ValueError(f"pairs must be a sequence of (from, to) sector pairs, got {pairs!r}") from None
    for i, j in out:
        if i == j:
            raise ValueError(f"pair ({i}, {j}) is not a cross-sector motion")
    twice = sorted({p for p in out if out.count(p) > 1})
    if twice:
        raise ValueError(f"pairs names {', '.join(f'{i}-{j}' for i, j in twice)} more than once")
    return out


def _collect_default_pair(job: tuple, robot: WearerArm | None = None) -> Collected:
    """:func:`collect_pair` with the default sampler and :class:`DemoPlanner` (runs in a worker process)."""
    model, i, j, child, opts = job
    if robot is None:
        urdf, srdf, margin, link_margins, n_threads = model
        robot = WearerArm(urdf, srdf if srdf is not None else False, security_margin=margin,
                          link_margins=link_margins, n_threads=n_threads)
    plan = DemoPlanner(robot, margins=opts.demo_margins, max_samples=opts.max_samples, seed=opts.seed,
                       timeout=opts.timeout)
    return collect_pair(query_sampler(robot, require_planning=opts.require_planning), plan, i, j, child,
                        opts.per_pair, opts.min_difference, opts.draws_per_pair, robot=robot)


def _pair_process(collect: Callable[[tuple], Collected], job: tuple, conn: Connection, parent: int) -> None:
    """A pair's own process: send ``("ok", collect(job))`` or ``("error", exception)`` to the build (process
    ``parent``), then leave at once."""
    child_sigint(signal.SIG_IGN)  # Ctrl-C goes to the build, which ends us
    die_with_parent(parent)
    try:
        msg: tuple[str, Any] = ("ok", collect(job))
    except Exception as exc:  # noqa: BLE001 (raised again by the build)
        msg = ("error", exc)
    except BaseException as exc:  # noqa: BLE001 (SystemExit, ...: an error of the pair, not an exit of the build)
        msg = ("error", RuntimeError(f"{type(exc).__name__}: {exc}"))
    try:
        try:
            conn.send(msg)
        except Exception:  # noqa: BLE001 (an exception that cannot be pickled: its text)
            conn.send(("error", RuntimeError(f"{type(msg[1]).__name__}: {msg[1]}")))
    finally:
        conn.close()
    # no interpreter finalisation: the result is sent, and it only makes the nanobind bindings list "leaked" objects
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)


def _collect_in_processes(
    collect: Callable[[tuple], Collected], jobs: Sequence[tuple], workers: int, done: Callable[[], Any]
) -> list[Collected]:
    """``collect(job)`` of every job, each in a fresh spawned process, at most ``workers`` at a time; ``done()`` after
    each.

    A pair whose process dies without a result (SIGKILL, the OOM killer, a crash) is run once more in a fresh
    process (the result is the same: a pair's work depends only on its job); if that one dies too, RuntimeError
    naming the pair and how its processes ended.  A pair that raises raises here at once.  Whatever ends the
    call (that, Ctrl-C, SIGTERM) kills the processes still running.
    """
    ctx = get_context("spawn")
    queue = deque(range(len(jobs)))
    deaths: dict[int, list[str]] = {}
    running: dict[int, tuple[BaseProcess, Connection]] = {}
    results: dict[int, Collected] = {}
    try:
        while queue or running:
            while queue and len(running) < workers:
                k = queue.popleft()
                recv, send = ctx.Pipe(duplex=False)
                proc = ctx.Process(target=_pair_process, args=(collect, jobs[k], send, os.getpid()), daemon=True)
                with sigint_blocked_for_children():  # a Ctrl-C now must not reach the child's imports
                    proc.start()
                    send.close()  # the child holds the only write end: EOF when it dies
                    running[k] = (proc, recv)
            wait([c for _, c in running.values()] + [p.sentinel for p, _ in running.values()])
            lost: list[int] = []
            for k, (proc, conn) in list(running.items()):
                if not conn.poll():
                    if proc.is_alive():
                        continue
                    message = None
                else:
                    try:
                        message = conn.recv()
                    except (EOFError, OSError):  # died before or while sending
                        message = None
                del running[k]
                conn.close()
                proc.join(timeout=30)  # it leaves right after sending, or is gone
                if proc.is_alive():
                    proc.kill()
                    proc.join(timeout=5)
                if message is None:
                    deaths.setdefault(k, []).append(exit_reason(proc.exitcode))
                    lost.append(k)
                elif message[0] == "ok":
                    results[k] = message[1]
                    done()
                else:
                    raise message[1]
            for k in lost:
                i, j = jobs[k][1:3]
                if len(deaths[k]) == 1:
                    log.warning("pair %d->%d: worker process %s; running the pair again in a fresh process",
                                i, j, deaths[k][0])
                    queue.appendleft(k)
            twice = [k for k in lost if len(deaths[k]) > 1]
            if twice:
                said = ", ".join(f"{jobs[k][1]}->{jobs[k][2]} (worker process {deaths[k][0]}, retry in a fresh "
                                 f"process {deaths[k][1]})" for k in twice)
                raise RuntimeError(f"pair{'s' if len(twice) > 1 else ''} {said} lost: no library built (a library "
                                   "needs every pair)")
    finally:
        for proc, conn in running.values():
            if proc.is_alive():
                proc.kill()
        for proc, conn in running.values():
            proc.join(timeout=5)
            conn.close()
    return [results[k] for k in range(len(jobs))]


def collect_default_demos(
    robot: WearerArm, opts: LibraryBuildOptions
) -> tuple[dict[tuple[int, int], Collected], Counter[str]]:
    """Demos of every pair of ``opts.pairs`` with :func:`query_sampler` and :class:`DemoPlanner`, and the summed counters.

    ``opts.workers`` > 1 runs the pairs in up to that many processes at once, a fresh one per pair with a copy of
    ``robot`` (same files and margins); the result is the same as with one (each pair has its own seed), unless a
    demo hits the wall-clock ``opts.timeout``.  A pair whose process dies (killed, out of memory) is run once more;
    if it dies again, RuntimeError naming it (:func:`_collect_in_processes`).
    """
    children = np.random.SeedSequence(opts.seed).spawn(len(opts.pairs))
    model = (robot.files.urdf, robot.files.srdf, robot.security_margin, dict(robot.link_margins), robot.n_threads)
    jobs = [(model, i, j, child, opts) for (i, j), child in zip(opts.pairs, children)]
    from tqdm.contrib.logging import logging_redirect_tqdm

    from ..progress import progress_bar

    with progress_bar(total=len(jobs), desc="library pairs", unit="pair", enabled=opts.progress) as bar:
        if opts.workers > 1 and len(jobs) > 1:
            # a warning (a pair run again) on a line of its own, not glued to the bar's
            with logging_redirect_tqdm() if opts.progress else contextlib.nullcontext():
                results = _collect_in_processes(_collect_default_pair, jobs, opts.workers, bar.update)
        else:
            results = []
            for job in jobs:
                results.append(_collect_default_pair(job, robot))
                bar.update()
    stats: Counter[str] = Counter()
    for r in results:
        stats.update(r[4])
    return dict(zip(opts.pairs, results)), stats


def learn_demos(
    collected: Mapping[tuple[int, int], Collected], per_step: int, options: DMPOptions
) -> dict[tuple[int, int], PairDemos]:
    """Per pair, resample each demo's DOF3/DOF4 (``per_step`` samples per step) and learn its forward and reverse DMP."""
    data: dict[tuple[int, int], PairDemos] = {}
    for (i, j), (starts, goals, waypoints, margins, _) in collected.items():
        pd = PairDemos(starts, goals, waypoints, margins)
        for W in pd.waypoints:
            demo = resample_waypoints(W[:, 2:], per_step)
            pd.forward.append(learn_dmp(demo, options))
            pd.reverse.append(learn_dmp(demo[::-1], options))
        data[(i, j)] = pd
        log.info("pair %d->%d: %d demonstrations", i, j, len(pd.starts))
    return data


def default_build_params(opts: LibraryBuildOptions, seconds: float) -> dict:
    """The ``build_params`` a default build records (saved in the library file's metadata)."""
    return {
        "builder": "PathLibrary.build_default",
        "per_pair": int(opts.per_pair),
        "seed": int(opts.seed),
        "pairs": [list(map(int, p)) for p in opts.pairs],
        "min_difference": float(opts.min_difference),
        "max_attempts": int(opts.draws_per_pair),
        "sampler": f"query_sampler(NECESSITY_REGIONS, require_planning={bool(opts.require_planning)})",
        "planner": f"DemoPlanner(margins={[float(m) for m in opts.demo_margins]}, links={list(POINTING_LINKS)}, "
                   f"max_samples={opts.max_samples}, timeout={opts.timeout:g})",
        "dmp_options": asdict(opts.dmp_options),
        "workers": int(opts.workers),
        "build_seconds": round(seconds, 1),
    }
