"""Animations of joint-space paths and the arc-length resampling behind them."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.pictures import GIF_SIGNATURE, assert_image
from PIL import Image

from tpee_ompl.model.sectors import cross_sector_trajectory
from tpee_ompl.viz import animate_path, resample_path


def test_resample_path_is_even_in_arc_length_and_keeps_the_ends():
    W = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 3.0]])
    R = resample_path(W, 9)
    assert R.shape == (9, 2)
    np.testing.assert_allclose(R[0], W[0])
    np.testing.assert_allclose(R[-1], W[-1])
    np.testing.assert_allclose(np.linalg.norm(np.diff(R, axis=0), axis=1), 0.5)
    assert resample_path(W[:1], 4).shape == (4, 2)


def test_animate_path_writes_a_bounded_gif(robot, aimed, tmp_path):
    q, target_b = aimed
    W = np.hstack([cross_sector_trajectory(1, 4), np.linspace([0.0, 0.0], q[2:], 7)])
    W = resample_path(W, 300)  # a long path: the animation must still have `frames` frames
    p0, u0 = robot.muzzle(W[0])
    out = animate_path(robot, W, tmp_path / "motion.gif", target_a=p0 + 3 * u0, target_b=target_b, frames=12, fps=8)
    assert_image(out, GIF_SIGNATURE, 30)
    with Image.open(out) as im:
        assert im.n_frames == 12
        width, height = im.size
        im.seek(11)
        last = np.asarray(im.convert("RGB"), dtype=float)
        im.seek(0)
        first = np.asarray(im.convert("RGB"), dtype=float)
    assert (width, height) == (480, 480)  # 6 in at the default 80 dpi
    # bounded by the frame count, not the 300 waypoints: at most one byte per pixel per frame
    assert out.stat().st_size < 12 * width * height
    assert np.abs(last - first).mean() > 0.1, "the arm should move between the first and last frames"


def test_bad_animation_inputs_raise_with_a_message(robot, aimed, tmp_path):
    q, _ = aimed
    with pytest.raises(ValueError, match=r"waypoints must have shape \(K, 4\)"):
        animate_path(robot, np.zeros((5, 3)), tmp_path / "a.gif")
    with pytest.raises(ValueError, match="unsupported animation format"):
        animate_path(robot, np.tile(q, (3, 1)), tmp_path / "a.avi")


@pytest.mark.parametrize("kw, match", [({"frames": 10**6}, "frames"), ({"frames": 2.5}, "frames"), ({"dpi": 0}, "dpi"),
                                       ({"fps": float("nan")}, "fps"), ({"elev": float("nan")}, "elev")])
def test_animation_settings_are_value_errors_before_any_frame_is_drawn(robot, tmp_path, kw, match):
    """(a million frames ran for hours; a NaN camera angle wrote empty frames; a float count was a TypeError)"""
    with pytest.raises(ValueError, match=match):
        animate_path(robot, [[0, 0, 0, 0], [0.5, 0.3, 1.0, 0.2]], tmp_path / "a.gif", **kw)
    assert not list(tmp_path.iterdir())


def test_resample_path_refuses_a_count_it_could_not_hold():
    with pytest.raises(ValueError, match="n"):
        resample_path([[0.0, 0.0], [1.0, 1.0]], 10**9)


def test_waypoints_that_are_strings_or_beyond_any_joint_are_refused_not_coerced(robot, tmp_path):
    """Strings were parsed, complex numbers lost their imaginary part with a warning, and 1e300 overflowed into a
    "NaN configuration" error after two numpy warnings."""
    import warnings

    from tpee_ompl.viz.animation import animate_path, resample_path

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for bad, match in (([["0.87", "0.35", "0", "0"], ["0.87", "0.35", "0.1", "0"]], "real numbers"),
                           ([[0.87 + 1j, 0.35, 0, 0], [0.87, 0.35, 0.1, 0]], "real numbers"),
                           ([[1e300, 0, 0, 0], [0, 0, 0, 0]], "beyond")):
            with pytest.raises(ValueError, match=match):
                animate_path(robot, bad, tmp_path / "x.gif", frames=2)
        with pytest.raises(ValueError, match="finite"):
            resample_path([[float("nan"), 0.0], [1.0, 0.0]], 5)
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("dpi", [5, 201])
def test_an_animation_resolution_that_breaks_matplotlib_or_memory_is_refused(robot, tmp_path, dpi):
    """dpi 1-5 crashed in FreeType (IndexError from the GIF writer); dpi 2000 took 576 MB a frame."""
    from tpee_ompl.viz.animation import animate_path

    with pytest.raises(ValueError, match="dpi"):
        animate_path(robot, [[0.87, 0.35, 0, 0], [0.87, 0.35, 0.1, 0]], tmp_path / "x.gif", frames=2, dpi=dpi)


@pytest.mark.parametrize("out", [None, 5, b"x.gif"])
def test_an_output_that_is_no_file_name_is_a_value_error_naming_it(robot, out):
    """animate_path raised a bare TypeError where save_scene says what is wrong."""
    from tpee_ompl.viz.animation import animate_path

    with pytest.raises(ValueError, match="out_path must be a file name"):
        animate_path(robot, [[0.87, 0.35, 0, 0], [0.87, 0.35, 0.1, 0]], out, frames=2)


def test_an_animation_whose_frames_and_resolution_together_would_take_gigabytes_is_refused(robot, tmp_path):
    """Each limit alone allowed 500 frames at dpi 200: about 3.6 GB."""
    from tpee_ompl.viz.animation import animate_path

    with pytest.raises(ValueError, match="frames x dpi"):
        animate_path(robot, [[0.87, 0.35, 0, 0], [0.87, 0.35, 0.1, 0]], tmp_path / "x.gif", frames=500, dpi=200)


def test_an_interrupted_animation_leaves_no_file_and_removes_only_the_empty_folders_it_made(robot, tmp_path,
                                                                                              monkeypatch):
    """Ctrl-C during animate left the folders made for -o (new/dir) behind, empty."""
    from matplotlib import animation

    def interrupted(self, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(animation.PillowWriter, "grab_frame", interrupted)
    W = np.hstack([cross_sector_trajectory(1, 4), np.zeros((7, 2))])
    (tmp_path / "kept").mkdir()
    with pytest.raises(KeyboardInterrupt):
        animate_path(robot, W, tmp_path / "kept" / "new" / "dir" / "m.gif", frames=3)
    assert [p.name for p in tmp_path.iterdir()] == ["kept"] and not any((tmp_path / "kept").iterdir())

    def someone_else_writes(self, **kwargs):
        (tmp_path / "new" / "theirs.txt").write_text("x")
        raise KeyboardInterrupt

    monkeypatch.setattr(animation.PillowWriter, "grab_frame", someone_else_writes)
    with pytest.raises(KeyboardInterrupt):
        animate_path(robot, W, tmp_path / "new" / "dir" / "m.gif", frames=3)
    assert [p.name for p in (tmp_path / "new").iterdir()] == ["theirs.txt"]  # not empty: kept


def test_an_interrupted_gif_is_not_encoded_from_the_frames_so_far(robot, tmp_path, monkeypatch):
    """writer.saving encoded the frames grabbed before a Ctrl-C (7 s after one at frame 300 of 500) into a file
    then deleted, and before the first frame its IndexError replaced the KeyboardInterrupt."""
    from matplotlib import animation

    grab, finished = animation.PillowWriter.grab_frame, []

    def interrupted_at_the_second(self, **kwargs):
        if len(self._frames) == 1:
            raise KeyboardInterrupt
        grab(self, **kwargs)

    monkeypatch.setattr(animation.PillowWriter, "grab_frame", interrupted_at_the_second)
    monkeypatch.setattr(animation.PillowWriter, "finish", lambda self: finished.append(1))
    W = np.hstack([cross_sector_trajectory(1, 4), np.zeros((7, 2))])
    with pytest.raises(KeyboardInterrupt):
        animate_path(robot, W, tmp_path / "m.gif", frames=3)
    assert finished == [] and list(tmp_path.iterdir()) == []


def test_animate_path_shows_a_progress_bar_with_the_time_left_and_writes_the_same_gif(robot, tmp_path, capsys,
                                                                                       monkeypatch):
    """500 frames took 45-68 s without a word: the bar counts frames drawn, then encoded."""
    import tpee_ompl.viz._common as common

    monkeypatch.setattr(common, "PROGRESS_DELAY", 0.0)  # the bar appears after 2 s: now at once
    W = np.hstack([cross_sector_trajectory(1, 4), np.zeros((7, 2))])
    quiet = animate_path(robot, W, tmp_path / "quiet.gif", frames=4)
    assert capsys.readouterr().err == ""
    phases, add = [], common.Progress.add

    def spy(self, units, phase=None):  # what the bar is told, whatever tqdm redraws (at most every 0.1 s)
        phases.append(phase)
        add(self, units, phase)

    monkeypatch.setattr(common.Progress, "add", spy)
    shown = animate_path(robot, W, tmp_path / "shown.gif", frames=4, progress=True)
    named = [p for p in phases if p is not None]
    assert named == ["frame 1/4", "frame 2/4", "frame 3/4", "frame 4/4", "encoding"] and len(phases) == 8
    lines = capsys.readouterr().err.replace("\r", "\n").split("\n")
    # (stderr is not a terminal under capsys: the progress comes as lines, tpee_ompl.progress)
    assert lines[-2].startswith("animate: 100 %,") and "00:00 left" in lines[-2] and lines[-2].rstrip().endswith("encoding")
    assert shown.read_bytes() == quiet.read_bytes()
    with pytest.raises(ValueError, match="progress"):
        animate_path(robot, W, tmp_path / "x.gif", frames=4, progress="yes")
