"""The tpee-ompl command line: output, JSON, and one-line errors with non-zero exit codes."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tpee_ompl.cli.main import main
from tpee_ompl.model.sectors import posture_preset

START = [*posture_preset(1), 0.0, 0.0]
GOAL = [*posture_preset(4), 0.0, 0.0]


def _args(*extra: str) -> list[str]:
    return ["plan", "--from", "1", "--to", "4", "--start", *map(str, START), "--goal", *map(str, GOAL), *extra]


def test_plan_with_rrtconnect_prints_a_valid_path_as_json(capsys):
    assert main(_args("--planner", "rrtconnect", "--time", "2", "--json")) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["exact"] and out["valid"]
    np.testing.assert_allclose(out["path"][0], START, atol=1e-6)
    np.testing.assert_allclose(out["path"][-1], GOAL, atol=1e-6)
    assert out["collision_checks"] > 0


def test_plan_prints_validity_and_length_in_text(capsys):
    assert main(_args("--planner", "rrtconnect", "--time", "2")) == 0
    out = capsys.readouterr().out
    assert "valid (checkMotion on every segment): True" in out and "length" in out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["plan", "--from", "1", "--to", "9"], "unknown sector 9"),
        (["plan", "--from", "1", "--to", "4", "--planner", "magic"], "invalid choice"),
        (["plan", "--from", "1", "--to", "4", "--start", "nan", "0", "0", "0", "--goal", "0", "1", "0", "0"], "not a finite number"),
        (["plan", "--from", "1", "--to", "4", "--samples", "0"], "positive integer"),
    ],
)
def test_bad_arguments_exit_non_zero_with_one_line(capsys, argv, message):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code != 0
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


def test_start_in_collision_is_one_line_on_stderr(capsys):
    argv = ["plan", "--from", "1", "--to", "4", "--start", "-0.085", "0.299", "-0.799", "-1.202", "--goal", *map(str, GOAL)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "in collision" in err


def test_missing_urdf_is_one_line_on_stderr(capsys, tmp_path):
    assert main(_args("--urdf", str(tmp_path / "missing.urdf"))) == 2
    assert "URDF file not found" in capsys.readouterr().err


def _is_nonblank_png(path) -> bool:
    import matplotlib.image as mpimg

    return path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and float(mpimg.imread(path)[..., :3].std()) > 0.02


def test_show_without_arguments_draws_the_default_scene(tmp_path, capsys):
    out = tmp_path / "scene.png"
    assert main(["show", "-o", str(out)]) == 0
    assert _is_nonblank_png(out) and out.stat().st_size > 20_000


def test_animate_writes_a_gif_of_a_planned_motion(tmp_path):
    out = tmp_path / "m.gif"
    assert main(["animate", "--planner", "rrtconnect", "--time", "2", "--start", *map(str, START),
                 "--goal", *map(str, GOAL), "--frames", "6", "-o", str(out)]) == 0
    assert out.read_bytes()[:6] in (b"GIF89a", b"GIF87a")


def test_animate_with_unreadable_path_file_is_one_line(tmp_path, capsys):
    bad = tmp_path / "p.json"
    bad.write_text("{not json")
    assert main(["animate", "--path", str(bad), "-o", str(tmp_path / "m.gif")]) == 2
    assert "cannot read a path" in capsys.readouterr().err


def test_view_without_meshcat_says_what_to_install(capsys):
    try:
        import meshcat  # noqa: F401
    except ImportError:
        assert main(["view", "--no-browser"]) == 2
        assert "pip install" in capsys.readouterr().err
    else:
        pytest.skip("meshcat is installed: the viewer would block")


def test_bench_help_shows_an_example(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["bench", "--help"])
    assert exc.value.code == 0
    assert "example:" in capsys.readouterr().out


def test_aim_prints_a_collision_free_aim_with_clear_line_of_sight(capsys):
    assert main(["aim", "--target", "5", "2", "1.5", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["collision_free"] and out["line_of_sight_clear"] and out["aim_error_m"] < 1e-9


def test_aim_at_a_target_inside_the_body_is_one_line(capsys):
    assert main(["aim", "--target", "0", "0", "1.2"]) == 2
    assert "inside" in capsys.readouterr().err


def test_track_jitter_on_a_boundary_causes_no_cross_sector_motion(capsys):
    assert main(["track", "--script", "jitter", "--duration", "5", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["events"]["cross-sector"] <= 1 and out["events"]["aim"] > 0


def test_library_query_without_a_library_file_is_one_line(capsys, tmp_path):
    assert main(["library", "stats", "--library", str(tmp_path / "none.npz")]) == 2
    err = capsys.readouterr().err
    assert "not found" in err and err.count("\n") == 1
