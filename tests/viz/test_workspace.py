"""Where the barrel can point: sector pointing ranges and the Monte Carlo pointing workspace."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.pictures import PNG_SIGNATURE, assert_image

from tpee_ompl.viz import pointing_workspace, sample_pointing_workspace, sector_pointing_range


def test_sample_pointing_workspace_is_seeded_and_line_of_sight_clear(robot):
    a = sample_pointing_workspace(robot, 300, np.random.default_rng(7), ranges=(0.3, 0.8))
    b = sample_pointing_workspace(robot, 300, np.random.default_rng(7), ranges=(0.3, 0.8))
    np.testing.assert_array_equal(a.points, b.points)
    assert 0 < a.n_valid <= 300
    assert a.points.shape == (len(a.range), 3) == (len(a.sector), 3)
    assert set(np.unique(a.range)) <= {0.3, 0.8}
    assert set(np.unique(a.sector)) <= {1, 2, 3, 4}
    # every configuration contributes at most one point per range
    assert len(a.points) <= 2 * a.n_valid


def test_pointing_workspace_draws_four_panels_into_a_png(robot, tmp_path):
    out = tmp_path / "workspace.png"
    fig = pointing_workspace(robot, 600, np.random.default_rng(0), out, color_by="range")
    assert len(fig.axes) == 4
    assert_image(out, PNG_SIGNATURE, 40)


def test_pointing_workspace_rejects_an_unknown_colouring(robot):
    with pytest.raises(ValueError, match="color_by"):
        pointing_workspace(robot, 10, np.random.default_rng(0), color_by="x")


def test_sector_pointing_range_marks_reachable_directions(robot):
    dirs, ok = sector_pointing_range(robot, 4, n_dirs=200)
    assert dirs.shape == (200, 3)
    np.testing.assert_allclose(np.linalg.norm(dirs, axis=1), 1.0)
    assert 0.5 < ok.mean() < 1.0  # most directions reachable, some blind (behind the body)


@pytest.mark.parametrize("kw, match", [({"n_samples": 2.5}, "n_samples"), ({"n_samples": 10**12}, "n_samples"),
                                       ({"rng": 1}, "rng"), ({"ranges": [np.inf]}, "ranges"), ({"ranges": 0.5}, None)])
def test_workspace_sampling_settings_are_value_errors_naming_them(robot, kw, match):
    args = {"n_samples": 50, "rng": np.random.default_rng(1), **kw}
    if match is None:  # one range given as a number is one range
        assert len(sample_pointing_workspace(robot, **args).points) > 0
        return
    with pytest.raises(ValueError, match=match):
        sample_pointing_workspace(robot, **args)


def test_sector_pointing_range_refuses_no_directions(robot):
    with pytest.raises(ValueError, match="n_dirs"):
        sector_pointing_range(robot, 1, n_dirs=0)  # warned "mean of empty slice" and drew nan %


def test_a_refused_argument_leaves_no_folder_for_the_figure_behind(robot, tmp_path):
    with pytest.raises(ValueError, match="n_samples"):
        pointing_workspace(robot, 0, np.random.default_rng(0), tmp_path / "new" / "sub" / "ws.png")
    assert list(tmp_path.iterdir()) == []


def test_pointing_workspace_shows_a_progress_bar_with_the_time_left_and_draws_the_same_png(robot, tmp_path, capsys,
                                                                                            monkeypatch):
    """200,000 samples took 38 s without a word: the bar counts sampling, plotting and drawing, weighted by time."""
    import tpee_ompl.viz._common as common

    monkeypatch.setattr(common, "PROGRESS_DELAY", 0.0)  # the bar appears after 2 s: now at once
    pointing_workspace(robot, 300, np.random.default_rng(0), tmp_path / "quiet.png")
    assert capsys.readouterr().err == ""
    phases, add = [], common.Progress.add

    def spy(self, units, phase=None):
        phases.append(phase)
        add(self, units, phase)

    monkeypatch.setattr(common.Progress, "add", spy)
    pointing_workspace(robot, 300, np.random.default_rng(0), tmp_path / "shown.png", progress=True)
    named = [p for p in phases if p is not None]
    assert list(dict.fromkeys(named)) == ["collision checks", "lines of sight", "plotting", "drawing"]
    assert named.count("drawing") == 4  # one step per panel, each drawn once
    lines = [line.rstrip() for line in capsys.readouterr().err.replace("\r", "\n").split("\n") if line]
    assert lines[-1].startswith("workspace: 100 %,") and lines[-1].endswith("drawing")  # (lines: not a terminal)
    percent = [int(line.split("%")[0].split()[-1]) for line in lines]
    assert percent == sorted(percent)  # never past the total (tqdm then shows 0%)
    assert (tmp_path / "shown.png").read_bytes() == (tmp_path / "quiet.png").read_bytes()
    sample_pointing_workspace(robot, 50, np.random.default_rng(0), progress=True)
    assert "lines of sight" in capsys.readouterr().err


def test_a_workspace_with_no_collision_free_configuration_says_so_in_a_warning(caplog):
    """Every state in collision (a margin of 0.5 m): the figure was drawn empty, only its title saying "0 of N
    configurations collision-free", and tpee-ompl workspace printed "wrote ... (N samples, seed 0)"."""
    import logging

    from tpee_ompl.model.wearer_arm import WearerArm

    with caplog.at_level(logging.WARNING, logger="tpee_ompl.viz.workspace"):
        pointing_workspace(WearerArm(security_margin=0.5), 50, np.random.default_rng(0))
    assert "none of the 50 configurations drawn is collision-free" in caplog.text
