"""Still pictures: the scene, the line of sight, invalid configurations, the sectors overlay."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.pictures import PNG_SIGNATURE, assert_image
from matplotlib.colors import to_hex

from tpee_ompl.model.sectors import cross_sector_trajectory
from tpee_ompl.viz import LOS_BLOCKED, LOS_CLEAR, render_scene, save_scene
from tpee_ompl.viz.meshes import scene_mesh


def test_save_scene_writes_a_non_blank_png_and_reuses_the_scene_mesh(robot, aimed, tmp_path):
    q, target = aimed
    mesh = scene_mesh(robot)
    out = save_scene(robot, q, tmp_path / "scene.png", target=target)
    assert scene_mesh(robot) is mesh, "the wearer's faces are computed once per robot, then cached"
    assert_image(out, PNG_SIGNATURE, 20)


def test_scene_line_of_sight_is_green_when_clear_and_red_when_blocked(robot, aimed):
    q, target = aimed
    assert robot.line_of_sight_clear(q, target)
    fig = render_scene(robot, q, target=target)
    colors = {to_hex(line.get_color()) for line in fig.axes[0].lines}
    assert LOS_CLEAR in colors and LOS_BLOCKED not in colors
    assert "LOS clear" in fig.axes[0].get_title()

    p, _ = robot.muzzle(q)
    helmet_centre = np.array([-0.005, 0.0, 1.69])
    blocked = p + 2.0 * (helmet_centre - p)  # straight through the wearer's helmet
    assert not robot.line_of_sight_clear(q, blocked)
    fig = render_scene(robot, q, target=blocked)
    colors = {to_hex(line.get_color()) for line in fig.axes[0].lines}
    assert LOS_BLOCKED in colors
    assert "BLOCKED" in fig.axes[0].get_title()


def test_invalid_configuration_is_flagged(robot):
    rng = np.random.default_rng(3)
    Q = rng.uniform(robot.lower, robot.upper, size=(400, 4))
    q_bad = Q[~robot.are_valid(Q)][0]
    fig = render_scene(robot, q_bad)
    assert "INVALID" in fig.axes[0].get_title()


def test_a_scene_with_sectors_labels_all_four_and_saves_a_png_with_the_path(robot, aimed, tmp_path):
    q, target = aimed
    W = np.hstack([cross_sector_trajectory(1, 4), np.linspace([0.0, 0.0], q[2:], 7)])
    out = save_scene(robot, q, tmp_path / "sectors.png", target=target, sectors=True, path=W)
    assert_image(out, PNG_SIGNATURE, 20)
    texts = {t.get_text().strip() for t in render_scene(robot, q, sectors=True).axes[0].texts}
    assert {"S1", "S2", "S3", "S4"} <= texts


def test_bad_scene_inputs_raise_with_a_message(robot, aimed):
    q, _ = aimed
    with pytest.raises(ValueError, match="target must be 3"):
        render_scene(robot, q, target=[1.0, 2.0])
    with pytest.raises(ValueError, match="shape"):
        render_scene(robot, q[:3])
    with pytest.raises(ValueError, match="azim"):
        render_scene(robot, q, azim=float("inf"))  # as save_scene: a non-finite angle drew an empty picture


@pytest.mark.parametrize(("kw", "match"), [
    ({"q": [1e300, 0.0, 0.0, 0.0]}, r"q holds 1e\+300, beyond the \+/-1000 rad"),  # drew a 2901-px-wide title
    ({"q": [0.0, 0.0, 0.0, -1001.0]}, "q holds 1001"),
    ({"sectors": "yes"}, "sectors must be True or False"),
    ({"max_extent": 0.0}, "max_extent"),
    ({"max_extent": float("nan")}, "max_extent"),
    ({"robot": None}, "robot must be a WearerArm"),  # was an AttributeError ('check_config')
])
def test_a_scene_refuses_a_q_beyond_any_joint_and_bad_settings_naming_them(robot, tmp_path, kw, match):
    args = {"robot": robot, "q": np.zeros(4), **kw}
    with pytest.raises(ValueError, match=match):
        save_scene(args.pop("robot"), args.pop("q"), tmp_path / "scene.png", **args)
    assert not (tmp_path / "scene.png").exists()


def test_the_sectors_picture_refuses_a_robot_that_is_not_a_wearer_arm(tmp_path):
    from tpee_ompl.viz import render_sectors

    with pytest.raises(ValueError, match="robot must be a WearerArm, got NoneType"):
        render_sectors(None, tmp_path / "sectors.png")


def test_a_figure_name_without_an_image_suffix_is_refused_before_any_folder_is_made(robot, tmp_path):
    with pytest.raises(ValueError, match="image suffix"):
        save_scene(robot, np.zeros(4), tmp_path / "new" / "scene.txt")
    assert not (tmp_path / "new").exists()
    with pytest.raises(ValueError, match="elev"):
        save_scene(robot, np.zeros(4), tmp_path / "s.png", elev=float("nan"))  # drew an empty picture
    with pytest.raises(ValueError, match="out_path"):
        save_scene(robot, np.zeros(4), None)


def test_a_postscript_figure_is_written_without_matplotlibs_transparency_warning(robot, tmp_path, caplog):
    """The scene's translucent faces made matplotlib log "The PostScript backend does not support transparency"."""
    import logging

    import numpy as np

    from tpee_ompl.viz import save_scene

    with caplog.at_level(logging.WARNING):
        save_scene(robot, np.radians([50, 20, 17, -37]), tmp_path / "scene.eps", dpi=20)
    assert (tmp_path / "scene.eps").stat().st_size > 0
    assert not [r for r in caplog.records if "transparency" in r.getMessage()]


@pytest.mark.parametrize("offset", [0.0, 1e-12])
def test_a_target_at_the_muzzle_is_refused_naming_the_target_not_drawn_with_aim_error_90(robot, aimed, offset):
    """A target at the muzzle has no direction; the title said "aim error 90.0°"."""
    q, _ = aimed
    p, _ = robot.muzzle(q)
    with pytest.raises(ValueError, match=r"^target \(.*\) m is at the muzzle .*no direction"):
        render_scene(robot, q, target=p + offset)
    assert "aim error" in render_scene(robot, q, target=p + 0.05).axes[0].get_title()  # 5 cm off: a direction
