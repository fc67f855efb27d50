"""``tpee-ompl show|animate|view``: pictures written, one-line errors."""

from __future__ import annotations

import pytest
from helpers.cli_queries import start_goal_args
from helpers.pictures import GIF_SIGNATURE, PNG_SIGNATURE, assert_image

from tpee_ompl.cli.main import main


def test_show_without_arguments_draws_the_default_scene(tmp_path, capsys):
    out = tmp_path / "scene.png"
    assert main(["show", "-o", str(out)]) == 0
    assert_image(out, PNG_SIGNATURE, 20)


def test_animate_writes_a_gif_of_a_planned_motion(tmp_path):
    out = tmp_path / "m.gif"
    argv = ["animate", "--planner", "rrtconnect", "--time", "2", *start_goal_args(), "--frames", "6", "-o", str(out)]
    assert main(argv) == 0
    assert out.read_bytes()[:6] in (b"GIF89a", b"GIF87a")
    assert_image(out, GIF_SIGNATURE, 1)


def test_animate_with_unreadable_path_file_is_one_line(tmp_path, capsys):
    bad = tmp_path / "p.json"
    bad.write_text("{not json")
    assert main(["animate", "--path", str(bad), "-o", str(tmp_path / "m.gif")]) == 1  # bad content: a runtime error
    assert "cannot read a path" in capsys.readouterr().err
    assert not (tmp_path / "m.gif").exists()


def test_view_without_meshcat_says_what_to_install_and_exits_1(capsys, monkeypatch):
    """A missing optional dependency exited 2, the code of a usage error, though the arguments were right."""
    try:
        import meshcat  # noqa: F401
    except ImportError:
        pass
    else:  # the viewer would block: its import fails as without meshcat
        import sys

        monkeypatch.setitem(sys.modules, "meshcat", None)
    assert main(["view", "--no-browser"]) == 1
    assert capsys.readouterr().err == ("tpee-ompl view: error: the interactive viewer needs meshcat: pip install "
                                       "meshcat (or pip install 'tpee_ompl[viewer]')\n")


def test_show_writes_exactly_the_named_file_and_replaces_it_only_with_force(tmp_path, capsys):
    out = tmp_path / "scene.svg"
    assert main(["show", "-o", str(out)]) == 0
    assert f"wrote {out} " in capsys.readouterr().out
    assert out.read_bytes().lstrip().startswith(b"<?xml") and [p.name for p in tmp_path.iterdir()] == ["scene.svg"]
    out.write_bytes(b"older")
    assert main(["show", "-o", str(out)]) == 2
    assert "--force" in capsys.readouterr().err and out.read_bytes() == b"older"
    assert main(["show", "-o", str(out), "--force"]) == 0
    assert out.read_bytes().lstrip().startswith(b"<?xml") and [p.name for p in tmp_path.iterdir()] == ["scene.svg"]


def test_animate_reads_a_path_file_and_writes_the_gif(tmp_path, capsys):
    from helpers.cli_queries import GOAL, START
    from helpers.hostile_files import write_path_file

    path = write_path_file(tmp_path / "p.json", [START, GOAL])
    out = tmp_path / "m.gif"
    assert main(["animate", "--path", str(path), "--frames", "3", "-o", str(out)]) == 0
    assert_image(out, GIF_SIGNATURE, 1)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.gif", "p.json"]  # no temporary file left


def test_show_with_a_target_at_the_muzzle_is_a_usage_error_naming_the_target(tmp_path, capsys):
    """``show --target`` at the muzzle drew the scene with "aim error 90.0 deg" (the direction was noise)."""
    import numpy as np

    from tpee_ompl.model.wearer_arm import default_robot

    q = [0.87, 0.35, 0.3, -0.6]
    p, _ = default_robot().muzzle(np.array(q))
    out = tmp_path / "new" / "s.png"
    assert main(["show", "--q", *map(repr, q), "--target", *map(repr, p.tolist()), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "--target: target (" in err and "at the muzzle" in err and err.count("\n") == 1
    assert not (tmp_path / "new").exists()


def test_the_default_scene_is_aimed_by_the_packages_ik_from_the_sector_select_sector_picks(tmp_path, capsys):
    """The default scene was hand-rounded: sector 4 where select_sector picks 3, aim error 1.2 deg."""
    import numpy as np

    from tpee_ompl.cli.pictures import DEFAULT_SCENE_TARGET, default_scene
    from tpee_ompl.model.pointing import aim_errors
    from tpee_ompl.model.sectors import posture_preset, select_sector
    from tpee_ompl.model.wearer_arm import default_robot

    robot = default_robot()
    q, target = default_scene(robot)
    assert np.array_equal(target, DEFAULT_SCENE_TARGET)
    assert np.allclose(q[:2], posture_preset(select_sector(target)))
    assert abs(aim_errors(robot, q, target)[2]) < 1e-9
    assert robot.is_valid(q) and robot.line_of_sight_clear(q, target)
    assert main(["show", "-o", str(tmp_path / "s.png")]) == 0
    assert f"q = {np.round(q, 4).tolist()} rad, valid: True" in capsys.readouterr().out


def test_show_with_a_target_and_no_q_aims_the_arm_at_that_target(tmp_path, capsys, monkeypatch):
    """The arm was aimed at the default target while the line of sight went to the one given."""
    import numpy as np

    from tpee_ompl.cli import pictures
    from tpee_ompl.model.pointing import AimingError, aim_errors
    from tpee_ompl.model.wearer_arm import default_robot

    robot, target = default_robot(), np.array([3.0, -2.0, 1.5])
    q, aimed = pictures.default_scene(robot, target)
    assert np.array_equal(aimed, target) and abs(aim_errors(robot, q, target)[2]) < 1e-9
    assert main(["show", "--target", "3", "-2", "1.5", "-o", str(tmp_path / "s.png")]) == 0
    assert f"q = {np.round(q, 4).tolist()} rad" in capsys.readouterr().out

    def cannot(*a, **k):
        raise AimingError("behind the wearer")

    monkeypatch.setattr("tpee_ompl.model.pointing.aim", cannot)
    assert main(["show", "--target", "3", "-2", "1.5", "-o", str(tmp_path / "t.png")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("tpee-ompl show: error: --target: target (3.0, -2.0, 1.5) m cannot be aimed at from sector")
    assert "give --q" in err and len(err.splitlines()) == 1 and not (tmp_path / "t.png").exists()


def test_an_interrupted_show_exits_130_and_removes_the_folders_it_made_for_the_output(tmp_path, capsys, monkeypatch):
    """Ctrl-C while ``show -o new/dir/s.png`` wrote left new/dir behind, empty."""
    from matplotlib.figure import Figure

    def interrupted(self, *args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(Figure, "savefig", interrupted)
    assert main(["show", "-o", str(tmp_path / "new" / "dir" / "s.png")]) == 130
    assert "interrupted" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_workspace_and_animate_show_a_progress_bar_unless_no_progress(tmp_path, capsys, monkeypatch):
    """``workspace`` (38 s at 200,000 samples) and ``animate`` (45-68 s at 500 frames) showed no progress."""
    import tpee_ompl.viz._common as common
    from helpers.cli_queries import GOAL, START
    from helpers.hostile_files import write_path_file

    monkeypatch.setattr(common, "PROGRESS_DELAY", 3600.0)  # (2 s by default: a loaded machine may take longer)
    assert main(["workspace", "--samples", "50", "-o", str(tmp_path / "w0.png")]) == 0
    assert capsys.readouterr().err == ""  # a run shorter than the delay prints no bar
    monkeypatch.setattr(common, "PROGRESS_DELAY", 0.0)
    assert main(["workspace", "--samples", "50", "-o", str(tmp_path / "w1.png")]) == 0
    assert "workspace: 100 %" in capsys.readouterr().err  # (stderr is not a terminal here: lines, not a bar)
    path = write_path_file(tmp_path / "p.json", [START, GOAL])
    assert main(["animate", "--path", str(path), "--frames", "3", "-o", str(tmp_path / "m1.gif")]) == 0
    assert "animate: 100 %" in capsys.readouterr().err
    assert main(["workspace", "--samples", "50", "--no-progress", "-o", str(tmp_path / "w2.png")]) == 0
    assert main(["animate", "--path", str(path), "--frames", "3", "--no-progress", "-o", str(tmp_path / "m2.gif")]) == 0
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize("given", [["--from", "1", "--to", "4"], ["--time", "5"], ["--queries", "planning_necessary"],
                                   ["--stall", "1000", "--seed", "1"]])
def test_animate_path_refuses_planning_options_given_at_their_default_values(tmp_path, capsys, given: list[str]):
    """--from 1 --to 4 (or any planning option at its default value) with --path were ignored without a word: the
    check compared the values with the defaults instead of asking whether the option was given."""
    from helpers.cli_queries import GOAL, START
    from helpers.hostile_files import write_path_file

    path = write_path_file(tmp_path / "p.json", [START, GOAL])
    out = tmp_path / "m.gif"
    assert main(["animate", "--path", str(path), *given, "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    named = " ".join(a for a in given if a.startswith("--"))
    assert err.endswith(f"--path animates the path in the file: {named} would be ignored"), err
    assert not out.exists()


def test_animate_path_refuses_a_plan_that_is_not_exact(tmp_path, capsys):
    """A ``plan --json`` file of an approximate plan ("exact": false, plan's exit 1) was animated without a word, while
    animate planning the motion itself refuses one ("found no exact path ...; nothing to animate")."""
    import json

    from helpers.cli_queries import GOAL, START

    doc = {"planner": "rrtstar", "from_sector": 1, "to_sector": 4, "query_id": 20, "status": "Approximate solution",
           "exact": False, "valid": True, "path": [list(START), list(GOAL)]}
    path = tmp_path / "approx.json"
    path.write_text(json.dumps(doc), encoding="utf-8")
    out = tmp_path / "m.gif"
    assert main(["animate", "--path", str(path), "-o", str(out)]) == 1
    err = capsys.readouterr().err.strip()
    assert err.endswith(f"--path {path}: its plan found no exact path (\"exact\": false, status 'Approximate "
                        "solution'); nothing to animate"), err
    assert not out.exists()
    path.write_text(json.dumps({**doc, "exact": "no"}), encoding="utf-8")
    assert main(["animate", "--path", str(path), "-o", str(out)]) == 1
    assert "'exact' must be true or false, got 'no'" in capsys.readouterr().err
    path.write_text(json.dumps({**doc, "exact": True, "status": "Exact solution"}), encoding="utf-8")
    assert main(["animate", "--path", str(path), "--frames", "2", "--no-progress", "-o", str(out)]) == 0
