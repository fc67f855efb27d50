"""``tpee-ompl show|animate|workspace|view``: pictures of the wearer and the arm (see :mod:`tpee_ompl.viz`)."""

from __future__ import annotations

import argparse
import json
from typing import TYPE_CHECKING

import numpy as np

from ..viz.animation import MAX_FRAMES, animate_path
from ..viz.workspace import MAX_WORKSPACE_SAMPLES
from ._common import (
    CliError,
    add_force_arg,
    add_model_args,
    angle,
    argument,
    check_input_file,
    check_model_args,
    check_output,
    default_of,
    finite,
    int_between,
    load_robot,
    nonempty,
    numpy_seed,
)
from .plan import add_plan_args, check_plan_args, plan_motion

if TYPE_CHECKING:
    from ..model.wearer_arm import WearerArm

__all__ = ["ANIMATION_SUFFIXES", "DEFAULT_SCENE_TARGET", "MAX_FRAMES", "cmd_animate", "cmd_show", "cmd_view",
           "cmd_workspace", "default_scene", "register"]

ANIMATION_SUFFIXES = (".gif", ".mp4")
"""What ``animate -o`` writes: a GIF (Pillow) or an MP4 (ffmpeg)."""
_LIMIT_TOL = 1e-6
"""Radians a ``--path`` waypoint may lie beyond a joint limit (the decimals ``plan --json`` prints)."""

DEFAULT_SCENE_TARGET = (4.0, 1.5, 1.9)
"""Metres: the target of the default scene (``show`` and ``view`` without ``--q``; :func:`default_scene`)."""


def default_scene(robot: WearerArm, target: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """A scene's configuration (4,), radians, and target (3,), metres: ``target`` (default :data:`DEFAULT_SCENE_TARGET`)
    aimed at by the aiming IK from the posture sector :func:`~tpee_ompl.model.sectors.select_sector` picks for it
    (the default: sector 3, q = (-50, 20, 7.4, -8.0) deg with the packaged model).  When ``robot`` cannot aim there:
    RuntimeError for the default target, :class:`~tpee_ompl.model.pointing.AimingError` (a ValueError) for a given
    one."""
    from ..model.pointing import AimingError, PointingGeometry, aim
    from ..model.sectors import select_sector

    given = target is not None
    target = np.array(target if given else DEFAULT_SCENE_TARGET, dtype=float)
    sector = select_sector(target)
    try:
        q = aim(target, sector, geometry=PointingGeometry.from_robot(robot))
    except AimingError as exc:
        said = (f"target {tuple(target.round(4).tolist())} m cannot be aimed at from sector {sector} with this model "
                f"({exc})")
        if given:
            raise AimingError(f"{said}; give --q to draw the arm elsewhere") from None
        raise RuntimeError(f"the default scene's {said}; give --q") from None
    return q, target


def cmd_show(args: argparse.Namespace) -> int:
    """Draw the wearer, the arm at q and the line of sight to the target into a PNG."""
    from ..viz._common import check_target_off_muzzle, image_suffixes, optional_target
    from ..viz.scene import save_scene

    check_output(args.output, "--output", args.force, image_suffixes())
    robot = load_robot(args)
    target = None
    if args.target is not None:
        with argument("--target"):
            target = optional_target(args.target)
    if args.q is None:  # aimed at the target given, else at the default one
        with argument("--target"):
            q, target = default_scene(robot, target)
    else:
        q = np.array(args.q)
    with argument("--q"):
        q = robot.check_config(q)
    with argument("--target"):
        check_target_off_muzzle(robot, q, target)
    out = save_scene(robot, q, args.output, target=target, sectors=args.sectors, force=args.force)
    print(f"wrote {out} (q = {np.round(q, 4).tolist()} rad, valid: {robot.is_valid(q)})")
    return 0


def _read_path(file: str, robot: WearerArm) -> np.ndarray:
    """The 'path' list of waypoints in a JSON file (e.g. from ``plan --json``): at least two waypoints (a motion) of
    the robot's ``nq`` finite numbers (JSON numbers, not strings or booleans) within its joint limits, and not marked
    ``"exact": false`` (an approximate plan, which ``animate`` does not draw); ValueError naming the file and the
    waypoint otherwise."""
    try:
        with open(file, encoding="utf-8") as fh:
            doc = json.load(fh)
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
        raise ValueError(f"cannot read a path from --path {file}: {exc}") from None
    W = doc.get("path") if isinstance(doc, dict) else None
    exact = doc.get("exact", True) if isinstance(doc, dict) else True  # plan --json says it; a hand-made file may not
    if exact is not True:
        status = doc.get("status")
        said = f", status {status[:80]!r}" if isinstance(status, str) else ""
        if exact is False:
            raise ValueError(f"--path {file}: its plan found no exact path (\"exact\": false{said}); nothing to "
                             "animate")
        raise ValueError(f"--path {file}: 'exact' must be true or false, got {exact!r}"[:300])
    if not isinstance(W, list) or not W:
        raise ValueError(f"--path {file}: expected a JSON object with a non-empty 'path' list of waypoints")
    if len(W) < 2:
        raise ValueError(f"--path {file}: a motion needs at least two waypoints, the 'path' list has one")
    nq = robot.nq
    for k, w in enumerate(W):
        try:
            ok = (isinstance(w, list) and len(w) == nq
                  and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in w)
                  and bool(np.all(np.isfinite(np.asarray(w, dtype=float)))))
        except OverflowError:  # an integer too large for a float
            ok = False
        if not ok:
            raise ValueError(f"--path {file}: waypoint {k} must be {nq} finite numbers, got {w!r}"[:300])
        out = np.flatnonzero((np.asarray(w) < robot.lower - _LIMIT_TOL) | (np.asarray(w) > robot.upper + _LIMIT_TOL))
        if len(out):
            d = int(out[0])
            raise ValueError(f"--path {file}: waypoint {k} is outside the joint limits (DOF{d + 1} = {w[d]:g} rad, "
                             f"limits [{robot.lower[d]:g}, {robot.upper[d]:g}])")
    return np.asarray(W, dtype=float)


def cmd_animate(args: argparse.Namespace) -> int:
    """Plan a cross-sector motion (or read one from --path JSON) and write an animation."""
    from matplotlib import animation

    check_output(args.output, "--output", args.force, ANIMATION_SUFFIXES)
    if args.output.lower().endswith(".mp4") and not animation.writers.is_available("ffmpeg"):
        raise CliError(f"--output {args.output}: writing .mp4 needs ffmpeg on PATH; write a .gif instead")
    if args.path:
        if args.plan_options_given:  # they plan a motion (even at their default values); --path animates the file's
            raise CliError(f"--path animates the path in the file: {' '.join(args.plan_options_given)} would be "
                           "ignored")
        check_input_file(args.path, "--path", "path file")
        check_model_args(args)
        robot = load_robot(args)
        W = _read_path(args.path, robot)
    else:
        check_plan_args(args)
        result, robot = plan_motion(args)
        if not result["exact"]:
            raise RuntimeError(f"{args.planner} found no exact path ({result['status']}); nothing to animate")
        W = np.asarray(result["path"])
    (pa, ua), (pb, ub) = robot.muzzle(W[0]), robot.muzzle(W[-1])
    out = animate_path(robot, W, args.output, target_a=pa + 3 * ua, target_b=pb + 3 * ub, frames=args.frames,
                       force=args.force, progress=not args.no_progress)
    print(f"wrote {out} ({len(W)} waypoints, {args.frames} frames)")
    return 0


def cmd_workspace(args: argparse.Namespace) -> int:
    """Monte-Carlo pointing workspace (the paper's Fig. 4) into a PNG."""
    from ..viz._common import image_suffixes
    from ..viz.workspace import pointing_workspace

    check_output(args.output, "--output", args.force, image_suffixes())
    robot = load_robot(args)
    pointing_workspace(robot, args.samples, np.random.default_rng(args.seed), args.output, force=args.force,
                       progress=not args.no_progress)
    print(f"wrote {args.output} ({args.samples} samples, seed {args.seed})")
    return 0


def cmd_view(args: argparse.Namespace) -> int:
    """Interactive 3-D view in meshcat (optional extra `viewer`)."""
    import time

    from ..viz.meshcat import view_meshcat

    robot = load_robot(args)
    q = np.array(args.q) if args.q is not None else default_scene(robot)[0]
    with argument("--q"):
        q = robot.check_config(q)
    # (main() runs every command with SIGTERM as Ctrl-C: a kill ends it and meshcat's server process goes too)
    view_meshcat(robot, q, open_browser=not args.no_browser)
    print("meshcat viewer running; press Ctrl-C to stop")
    while True:
        time.sleep(1.0)


def _add_no_progress_arg(p: argparse.ArgumentParser) -> None:
    p.add_argument("--no-progress", action="store_true",
                   help="no progress bar (shown on stderr, with the time left, when the drawing lasts more than 2 s)")


def register(sub: argparse._SubParsersAction, fmt: type) -> None:
    """Add the ``show``, ``animate``, ``workspace`` and ``view`` subcommands."""
    p = sub.add_parser("show", help="draw a scene into a PNG", formatter_class=fmt,
                       description="Draw the wearer, the arm and the line of sight.\n\nexample:\n"
                                   "  tpee-ompl show -o scene.png\n"
                                   "  tpee-ompl show --q 0.87 0.35 0.3 -0.6 --target 4 1.5 1.9 --sectors -o s.png")
    p.add_argument("--q", type=angle, nargs=4, metavar="Q",
                   help="DOF1..DOF4 in radians (default: aimed at --target, or at 4 1.5 1.9, from the sector "
                        "select_sector picks, by the aiming IK)")
    p.add_argument("--target", type=finite, nargs=3, metavar=("X", "Y", "Z"),
                   help="target point (m, world frame); without --q the arm aims at it")
    p.add_argument("--sectors", action="store_true", help="overlay the posture sectors")
    p.add_argument("-o", "--output", type=nonempty, default="scene.png", help="image file (.png, .pdf, .svg, ...; default scene.png)")
    add_force_arg(p)
    add_model_args(p)
    p.set_defaults(func=cmd_show)

    p = sub.add_parser("animate", help="animate a cross-sector motion (GIF/MP4)", formatter_class=fmt,
                       description="Plan a cross-sector motion and animate it, muzzle trace drawn.\n\nexample:\n"
                                   "  tpee-ompl animate --from 1 --to 4 --planner dimension-rrt -o motion.gif\n"
                                   "  tpee-ompl plan --from 2 --to 3 --json > p.json && "
                                   "tpee-ompl animate --path p.json -o m.gif")
    add_plan_args(p)
    p.add_argument("--path", type=nonempty, help="JSON file with a 'path' list of waypoints (e.g. from plan --json)")
    p.add_argument("--frames", type=int_between(2, MAX_FRAMES), default=default_of(animate_path, "frames"),
                   help=f"frames, 2..{MAX_FRAMES} (default %(default)s)")
    p.add_argument("-o", "--output", type=nonempty, default="motion.gif", help="a .gif or .mp4 file (default motion.gif)")
    add_force_arg(p)
    _add_no_progress_arg(p)
    p.set_defaults(func=cmd_animate)

    p = sub.add_parser("workspace", help="Monte-Carlo pointing workspace (Fig. 4)", formatter_class=fmt,
                       description="Sample collision-free configurations and draw where the barrel can point.\n\n"
                                   "example:\n  tpee-ompl workspace --samples 4000 -o workspace.png")
    p.add_argument("--samples", type=int_between(1, MAX_WORKSPACE_SAMPLES), default=4000,
                   help=f"configurations drawn, 1..{MAX_WORKSPACE_SAMPLES} (default %(default)s)")
    p.add_argument("--seed", type=numpy_seed, default=0, help="sampling seed, 0..2^32-1 (default 0)")
    p.add_argument("-o", "--output", type=nonempty, default="workspace.png", help="image file (default workspace.png)")
    add_force_arg(p)
    _add_no_progress_arg(p)
    add_model_args(p)
    p.set_defaults(func=cmd_workspace)

    p = sub.add_parser("view", help="interactive meshcat view (pip install 'tpee_ompl[viewer]')", formatter_class=fmt,
                       description="Open the model in Pinocchio's MeshcatVisualizer.\n\n"
                                   "example:\n  tpee-ompl view --q 0.87 0.35 0 0")
    p.add_argument("--q", type=angle, nargs=4, metavar="Q")
    p.add_argument("--no-browser", action="store_true")
    add_model_args(p)
    p.set_defaults(func=cmd_view)
