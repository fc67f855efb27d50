"""Headless rendering: scenes, animations, the pointing workspace, the optional meshcat viewer."""

from __future__ import annotations

import os
import sys
import time

os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np
import pytest
from matplotlib.colors import to_hex
from PIL import Image

from tpee_ompl import default_robot
from tpee_ompl.viz import scene as render
from tpee_ompl.model.sectors import cross_sector_trajectory, posture_preset

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def robot():
    return default_robot()


@pytest.fixture(scope="module")
def aimed(robot):
    """Sector-4 posture aiming up and forward, with a target 3 m along the barrel."""
    q = np.concatenate([posture_preset(4), [0.3, -0.6]])
    p, u = robot.muzzle(q)
    return q, p + 3.0 * u


def _pixels_std(path) -> float:
    with Image.open(path) as im:
        return float(np.asarray(im.convert("RGB"), dtype=float).std())


def _assert_image(path, signature: bytes, min_kb: float) -> None:
    data = path.read_bytes()
    assert data[: len(signature)] == signature
    assert len(data) > min_kb * 1024
    assert _pixels_std(path) > 10.0, "image is (nearly) blank"


def test_save_scene_writes_a_non_blank_png_quickly(robot, aimed, tmp_path):
    q, target = aimed
    render.render_scene(robot, q)  # warm-up (fonts, mesh cache)
    t0 = time.perf_counter()
    out = render.save_scene(robot, q, tmp_path / "scene.png", target=target)
    assert time.perf_counter() - t0 < 2.0
    _assert_image(out, PNG_SIGNATURE, 20)


def test_scene_line_of_sight_is_green_when_clear_and_red_when_blocked(robot, aimed):
    q, target = aimed
    assert robot.line_of_sight_clear(q, target)
    fig = render.render_scene(robot, q, target=target)
    colors = {to_hex(line.get_color()) for line in fig.axes[0].lines}
    assert render._LOS_CLEAR in colors and render._LOS_BLOCKED not in colors
    assert "LOS clear" in fig.axes[0].get_title()

    p, _ = robot.muzzle(q)
    helmet_centre = np.array([-0.005, 0.0, 1.69])
    blocked = p + 2.0 * (helmet_centre - p)  # straight through the wearer's helmet
    assert not robot.line_of_sight_clear(q, blocked)
    fig = render.render_scene(robot, q, target=blocked)
    colors = {to_hex(line.get_color()) for line in fig.axes[0].lines}
    assert render._LOS_BLOCKED in colors
    assert "BLOCKED" in fig.axes[0].get_title()


def test_invalid_configuration_is_flagged(robot):
    rng = np.random.default_rng(3)
    Q = rng.uniform(robot.lower, robot.upper, size=(400, 4))
    q_bad = Q[~robot.are_valid(Q)][0]
    fig = render.render_scene(robot, q_bad)
    assert "INVALID" in fig.axes[0].get_title()


def test_scene_with_sectors_and_path(robot, aimed, tmp_path):
    q, target = aimed
    W = np.hstack([cross_sector_trajectory(1, 4), np.linspace([0.0, 0.0], q[2:], 7)])
    out = render.save_scene(robot, q, tmp_path / "sectors.png", target=target, sectors=True, path=W)
    _assert_image(out, PNG_SIGNATURE, 20)
    texts = {t.get_text().strip() for t in render.render_scene(robot, q, sectors=True).axes[0].texts}
    assert {"S1", "S2", "S3", "S4"} <= texts


def test_bad_inputs_raise_with_a_message(robot, aimed, tmp_path):
    q, _ = aimed
    with pytest.raises(ValueError, match="target must be 3"):
        render.render_scene(robot, q, target=[1.0, 2.0])
    with pytest.raises(ValueError, match="shape"):
        render.render_scene(robot, q[:3])
    with pytest.raises(ValueError, match=r"waypoints must have shape \(K, 4\)"):
        render.animate_path(robot, np.zeros((5, 3)), tmp_path / "a.gif")
    with pytest.raises(ValueError, match="unsupported animation format"):
        render.animate_path(robot, np.tile(q, (3, 1)), tmp_path / "a.avi")
    with pytest.raises(ValueError, match="color_by"):
        render.pointing_workspace(robot, 10, np.random.default_rng(0), color_by="x")


def test_resample_path_is_even_in_arc_length_and_keeps_the_ends():
    W = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 3.0]])
    R = render.resample_path(W, 9)
    assert R.shape == (9, 2)
    np.testing.assert_allclose(R[0], W[0])
    np.testing.assert_allclose(R[-1], W[-1])
    np.testing.assert_allclose(np.linalg.norm(np.diff(R, axis=0), axis=1), 0.5)
    assert render.resample_path(W[:1], 4).shape == (4, 2)


def test_animate_path_writes_a_bounded_gif(robot, aimed, tmp_path):
    q, target_b = aimed
    W = np.hstack([cross_sector_trajectory(1, 4), np.linspace([0.0, 0.0], q[2:], 7)])
    W = render.resample_path(W, 300)  # a long path: the animation must still have `frames` frames
    p0, u0 = robot.muzzle(W[0])
    t0 = time.perf_counter()
    out = render.animate_path(
        robot, W, tmp_path / "motion.gif", target_a=p0 + 3 * u0, target_b=target_b, frames=12, fps=8
    )
    assert time.perf_counter() - t0 < 15.0
    _assert_image(out, b"GIF8", 30)
    with Image.open(out) as im:
        assert im.n_frames == 12
        im.seek(11)
        last = np.asarray(im.convert("RGB"), dtype=float)
        im.seek(0)
        first = np.asarray(im.convert("RGB"), dtype=float)
    assert np.abs(last - first).mean() > 0.1, "the arm should move between the first and last frames"


def test_sample_pointing_workspace_is_seeded_and_line_of_sight_clear(robot):
    a = render.sample_pointing_workspace(robot, 300, np.random.default_rng(7), ranges=(0.3, 0.8))
    b = render.sample_pointing_workspace(robot, 300, np.random.default_rng(7), ranges=(0.3, 0.8))
    np.testing.assert_array_equal(a.points, b.points)
    assert 0 < a.n_valid <= 300
    assert a.points.shape == (len(a.range), 3) == (len(a.sector), 3)
    assert set(np.unique(a.range)) <= {0.3, 0.8}
    assert set(np.unique(a.sector)) <= {1, 2, 3, 4}
    # every configuration contributes at most one point per range
    assert len(a.points) <= 2 * a.n_valid


def test_pointing_workspace_figure(robot, tmp_path):
    out = tmp_path / "workspace.png"
    fig = render.pointing_workspace(robot, 600, np.random.default_rng(0), out, color_by="range")
    assert len(fig.axes) == 4
    _assert_image(out, PNG_SIGNATURE, 40)


def test_sector_pointing_range_marks_reachable_directions(robot):
    dirs, ok = render.sector_pointing_range(robot, 4, n_dirs=200)
    assert dirs.shape == (200, 3)
    np.testing.assert_allclose(np.linalg.norm(dirs, axis=1), 1.0)
    assert 0.5 < ok.mean() < 1.0  # most directions reachable, some blind (behind the body)


def test_view_meshcat_without_meshcat_says_how_to_install(robot, monkeypatch):
    monkeypatch.setitem(sys.modules, "meshcat", None)  # makes `import meshcat` raise ImportError
    with pytest.raises(ImportError, match="pip install meshcat") as info:
        render.view_meshcat(robot)
    assert isinstance(info.value, render.ViewerUnavailableError)


def test_view_meshcat_when_installed(robot, aimed):
    pytest.importorskip("meshcat", reason="optional viewer extra not installed")
    viz = render.view_meshcat(robot, aimed[0])
    viz.display(posture_preset(1).tolist() + [0.0, 0.0])
