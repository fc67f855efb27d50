"""``tpee-ompl library build|query|stats`` (parser from :func:`tpee_ompl.cli.library.build_parser`)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from helpers.hostile_files import make_unreadable

from tpee_ompl.cli._common import CliError
from tpee_ompl.cli.library import DEFAULT_LIBRARY, build_parser
from tpee_ompl.cli.main import main
from tpee_ompl.library import PathLibrary


def _run(argv: list[str]) -> int:
    args = build_parser().parse_args(argv)
    return args.func(args)


@pytest.fixture(scope="module")
def small_file(tmp_path_factory) -> str:
    path = tmp_path_factory.mktemp("lib") / "small.npz"
    assert _run(["library", "build", "--pairs", "1-2", "--per-pair", "1", "--max-samples", "200",
                 "--seed", "2", "--library", str(path)]) == 0
    return str(path)


def test_build_writes_a_loadable_library_with_its_parameters(robot, small_file: str) -> None:
    lib = PathLibrary.load(small_file, robot)
    assert list(lib.pairs) == [(1, 2)] and len(lib) == 1
    assert lib.build_params["per_pair"] == 1 and lib.build_params["seed"] == 2
    assert "max_samples=200" in lib.build_params["planner"]


@pytest.mark.parametrize("quiet", [False, True])
def test_build_shows_the_pairs_done_on_stderr_unless_no_progress(tmp_path, capsys, quiet) -> None:
    """A default build runs for minutes: it used to print nothing until the end."""
    argv = ["library", "build", "--pairs", "1-2", "2-3", "--per-pair", "1", "--max-samples", "200", "--seed", "2",
            "--library", str(tmp_path / "p.npz")] + (["--no-progress"] if quiet else [])
    assert _run(argv) == 0
    err = capsys.readouterr().err
    assert ("library pairs" in err and "2/2" in err) != quiet


def test_stats_describes_the_file(small_file: str, capsys) -> None:
    assert _run(["library", "stats", "--library", small_file]) == 0
    out = capsys.readouterr().out
    assert "1 demonstrations" in out and "1->2: 1" in out and '"per_pair": 1' in out


def test_query_from_a_named_set_prints_a_checked_path_as_json(robot, small_file: str, capsys) -> None:
    from tpee_ompl.model.queries import load_queries
    from tpee_ompl.planning.paths import motion_is_valid

    q = load_queries("planning_necessary")[0]
    assert (q.from_sector, q.to_sector) == (1, 2)
    code = _run(["library", "query", "--library", small_file, "--query-set", "planning_necessary", "--index", "0", "--json"])
    res = json.loads(capsys.readouterr().out)
    assert code == 0 and res["outcome"] in ("dmp", "repaired", "fallback")
    path = np.array(res["path"])
    np.testing.assert_allclose(path[0], q.start, atol=1e-6)
    np.testing.assert_allclose(path[-1], q.goal, atol=1e-6)
    assert motion_is_valid(robot, path)


def test_missing_library_file_names_the_fix(tmp_path) -> None:
    with pytest.raises(CliError, match="make library"):
        _run(["library", "stats", "--library", str(tmp_path / "none.npz")])


def test_query_without_a_query_names_the_missing_options(small_file: str) -> None:
    with pytest.raises(CliError, match="missing --start --goal"):
        _run(["library", "query", "--library", small_file, "--from", "1", "--to", "2"])


@pytest.mark.parametrize("extra, match", [(["--demo-margins", "nan"], "--demo-margins"), (["--pairs", "1-2", "1-2"], "--pairs")])
def test_bad_build_options_name_the_option(extra: list[str], match: str, tmp_path) -> None:
    with pytest.raises(CliError, match=match):
        _run(["library", "build", "--pairs", "1-2", "--library", str(tmp_path / "x.npz"), *extra])


@pytest.mark.parametrize("option, value", [("--workers", "0"), ("--per-pair", "100000000"), ("--max-attempts", "1e3"),
                                           ("--max-samples", "-1")])
def test_build_counts_are_positive_integers_up_to_ten_million(option: str, value: str, capsys) -> None:
    with pytest.raises(SystemExit):
        build_parser().parse_args(["library", "build", "--library", "x.npz", option, value])
    assert option in capsys.readouterr().err


def test_bad_sector_pair_is_a_usage_error(capsys) -> None:
    with pytest.raises(SystemExit):
        build_parser().parse_args(["library", "build", "--pairs", "2-2"])
    assert "two different numbers" in capsys.readouterr().err


def test_build_writes_nowhere_unless_told_where(capsys) -> None:
    """No default file: the packaged library lives inside the installed package."""
    with pytest.raises(SystemExit) as exc:
        build_parser().parse_args(["library", "build", "--pairs", "1-2"])
    assert exc.value.code == 2 and "--library" in capsys.readouterr().err


@pytest.mark.parametrize("sub", ["build", "query", "stats"])
def test_every_subcommand_help_shows_an_example_and_the_default_file(sub: str, capsys) -> None:
    with pytest.raises(SystemExit):
        build_parser().parse_args(["library", sub, "--help"])
    out = capsys.readouterr().out
    assert "example:" in out and f"tpee-ompl library {sub}" in out and str(DEFAULT_LIBRARY) in out


def test_the_query_examples_of_the_help_run(capsys) -> None:
    with pytest.raises(SystemExit):
        build_parser().parse_args(["library", "query", "--help"])
    examples = [line.split()[1:] for line in capsys.readouterr().out.splitlines()
                if line.strip().startswith("tpee-ompl library query")]
    assert len(examples) >= 2
    for argv in examples:
        assert main(argv) == 0, argv
        capsys.readouterr()


def test_build_never_replaces_a_library_without_force(robot, small_file: str, tmp_path) -> None:
    import shutil

    target = tmp_path / "lib.npz"
    shutil.copy(small_file, target)
    before = target.read_bytes()
    argv = ["library", "build", "--pairs", "1-2", "--per-pair", "1", "--max-samples", "200", "--seed", "3",
            "--library", str(target)]
    with pytest.raises(CliError, match="--force"):
        _run(argv)
    assert target.read_bytes() == before
    assert _run([*argv, "--force"]) == 0
    assert PathLibrary.load(target, robot).build_params["seed"] == 3
    assert [p.name for p in tmp_path.iterdir()] == ["lib.npz"]  # no temporary file left


@pytest.fixture(scope="module")
def other_model(tmp_path_factory) -> tuple[str, str]:
    """The packaged URDF with a comment added (another model hash) and the packaged SRDF."""
    from tpee_ompl.resources import model_file

    folder = tmp_path_factory.mktemp("model")
    text = model_file("wearer_arm.urdf").read_text(encoding="utf-8")
    urdf = folder / "copy.urdf"
    urdf.write_text(text.replace("\n", "\n<!-- my copy -->\n", 1), encoding="utf-8")
    srdf = folder / "copy.srdf"
    srdf.write_text(model_file("wearer_arm.srdf").read_text(encoding="utf-8"), encoding="utf-8")
    return str(urdf), str(srdf)


def test_a_library_for_another_urdf_is_built_inspected_and_planned_with(other_model, tmp_path, capsys) -> None:
    """With a custom URDF no command could build, show or pass a library for it (they all used the packaged model)."""
    from helpers.cli_queries import start_goal_args

    urdf, srdf = other_model
    model = ["--urdf", urdf, "--srdf", srdf]
    lib = tmp_path / "mine.npz"
    assert main(["library", "build", "--pairs", "1-4", "--per-pair", "1", "--max-samples", "200", "--workers", "1",
                 "--library", str(lib), *model]) == 0
    capsys.readouterr()
    assert main(["library", "stats", "--library", str(lib), *model]) == 0
    assert "1 demonstrations" in capsys.readouterr().out
    assert main(["library", "stats", "--library", str(lib)]) == 0  # the packaged model: described from its metadata
    assert "built for model" in capsys.readouterr().out
    assert main(["plan", "--from", "1", "--to", "4", *start_goal_args(), *model, "--library", str(lib), "--time", "0.05",
                 "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["planner"] == "library"


def test_plan_with_another_urdf_and_no_library_plans_with_dimension_rrt(other_model, capsys) -> None:
    """The default planner loaded the packaged library, built for the packaged model: every plan failed."""
    from helpers.cli_queries import start_goal_args

    urdf, srdf = other_model
    assert main(["plan", "--from", "1", "--to", "4", *start_goal_args(), "--urdf", urdf, "--srdf", srdf,
                 "--time", "0.05", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["planner"] == "dimension-rrt"
    assert main(["plan", "--from", "1", "--to", "2", "--planner", "rrtconnect", "--library", "x.npz"]) == 2
    assert "--library is read by --planner library" in capsys.readouterr().err
    assert main(["plan", "--from", "1", "--to", "4", *start_goal_args(), "--urdf", urdf, "--srdf", srdf,
                 "--planner", "library", "--time", "0.05"]) == 2
    assert "give --library FILE" in capsys.readouterr().err


def test_plan_with_the_packaged_model_named_explicitly_keeps_the_packaged_library(capsys):
    """The default is chosen by the model's hash, not by whether --urdf was given."""
    from helpers.cli_queries import start_goal_args

    from tpee_ompl.resources import model_file

    assert main(["plan", "--from", "1", "--to", "4", *start_goal_args(), "--urdf", str(model_file("wearer_arm.urdf")),
                 "--srdf", str(model_file("wearer_arm.srdf")), "--time", "0.05", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["planner"] == "library"


def test_another_model_gets_clear_errors_and_a_default_tracker_planner_without_the_packaged_library(other_model,
                                                                                                    capsys):
    """plan --urdf without --start/--goal failed at run time on the packaged query set's model ("regenerate the
    set"), track ignored a --library its planner does not read, and make_default_planner raised LibraryFileError."""
    from tpee_ompl import WearerArm
    from tpee_ompl.library.tracker import make_default_planner

    urdf, srdf = other_model
    assert main(["plan", "--from", "1", "--to", "4", "--urdf", urdf, "--srdf", srdf, "--time", "0.05"]) == 2
    assert "with --urdf give --start and --goal" in capsys.readouterr().err
    assert main(["track", "--planner", "dimension-rrt", "--library", "x.npz", "--duration", "1"]) == 2
    assert "--library is read by --planner default and library" in capsys.readouterr().err
    robot = WearerArm(urdf, srdf)
    plan = make_default_planner(robot, seed=1)
    from tpee_ompl.model.sectors import posture_preset

    path = plan(np.r_[posture_preset(1), 0.0, 0.0], np.r_[posture_preset(4), 0.0, 0.0], 1, 4)
    assert robot.are_valid(path).all()


def test_a_damaged_packaged_library_is_said_not_taken_for_another_models(tmp_path, monkeypatch, capsys):
    """An unreadable packaged library read as 'built for another model': plan quietly used dimension-rrt, track
    planned without it, and --planner library said it was built for another --urdf that nobody gave."""
    import tpee_ompl.resources as resources

    broken = tmp_path / "default.npz"
    broken.write_bytes(b"")
    monkeypatch.setattr(resources, "default_library_path", lambda: broken)  # read by storage.packaged_library_for
    from helpers.cli_queries import start_goal_args

    assert main(["plan", "--from", "1", "--to", "4", *start_goal_args(), "--time", "0.05"]) == 1
    assert "unreadable" in capsys.readouterr().err
    assert main(["track", "--duration", "1"]) == 1
    assert "unreadable" in capsys.readouterr().err


def test_plan_and_track_refuse_another_models_library_and_library_stats_describes_it(other_model, tmp_path, capsys):
    from helpers.cli_queries import start_goal_args

    urdf, srdf = other_model
    lib = tmp_path / "mine.npz"
    assert main(["library", "build", "--pairs", "1-4", "--per-pair", "1", "--max-samples", "200", "--workers", "1",
                 "--library", str(lib), "--urdf", urdf, "--srdf", srdf]) == 0
    capsys.readouterr()
    for argv in (["plan", "--from", "1", "--to", "4", *start_goal_args(), "--library", str(lib)],
                 ["track", "--duration", "1", "--library", str(lib)]):
        assert main(argv) == 2, argv
        assert "give the --urdf/--srdf it was built for" in capsys.readouterr().err
    # stats describes it from what the file says of itself (a helper: "describe a library file" refused it)
    assert main(["library", "stats", "--library", str(lib)]) == 0
    out = capsys.readouterr().out
    assert "built for model" in out and "pairs: 1->4" in out and '"per_pair": 1' in out


@pytest.mark.parametrize("command", [["plan", "--from", "1", "--to", "2", "--time", "0.05"], ["library", "stats"],
                                     ["library", "query", "--query-set", "planning_necessary"]])
def test_a_library_file_it_may_not_read_is_said_to_be_unreadable_by_permission(small_file: str, tmp_path, monkeypatch,
                                                                                capsys, command: list[str]) -> None:
    """A library of mode 000 was said to be "unreadable (truncated or not a library file): not an .npz archive"."""
    import shutil

    lib = tmp_path / "locked.npz"
    shutil.copy(small_file, lib)
    make_unreadable(lib, monkeypatch)
    assert main([*command, "--library", str(lib)]) == 1
    err = capsys.readouterr().err.strip()
    assert err.endswith(f"error: path library {lib} cannot be read (Permission denied)"), err
    assert len(err.splitlines()) == 1


@pytest.mark.parametrize("command", [[], ["plan"], ["aim"], ["track"], ["show"], ["animate"], ["workspace"], ["view"],
                                     ["bench"], ["library"], ["library", "build"], ["library", "query"],
                                     ["library", "stats"]])
def test_no_help_sends_the_reader_to_docs_which_the_wheel_does_not_ship(command: list[str], capsys) -> None:
    """``library build --help`` said "docs/dmp.md says why" of --dmp-scaling; docs/ is not in the wheel."""
    with pytest.raises(SystemExit):
        main([*command, "--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "docs/" not in out and ".md" not in out
    if command == ["library", "build"]:
        assert "absolute forcing shifts the detour unchanged" in out


_QUICK_PARALLEL_BUILD = ["library", "build", "--pairs", "1-2", "2-1", "--per-pair", "1", "--max-samples", "200",
                         "--seed", "5", "--demo-margins", "--workers", "2", "--no-progress"]


@pytest.mark.parametrize("times", [1, 2])
def test_a_killed_build_worker_is_run_again_once_then_the_build_fails_in_one_line_naming_the_pair(
        tmp_path, monkeypatch, capsys, caplog, times: int) -> None:
    """kill -9 of one worker 4 s into a build: "error: A process in the process pool was terminated abruptly while
    the future was running or pending.", exit 1, the two pairs already done thrown away."""
    import multiprocessing as mp

    from helpers.library_killers import arm

    arm(monkeypatch, tmp_path / "kills", pair=(2, 1), times=times)
    out = tmp_path / "lib.npz"
    code = main([*_QUICK_PARALLEL_BUILD, "--library", str(out)])
    captured = capsys.readouterr()
    assert "running the pair again in a fresh process" in caplog.text
    if times == 1:
        assert code == 0 and out.exists() and f"wrote {out}: 2 demonstrations in 2 pairs" in captured.out
    else:
        assert code == 1 and not out.exists() and captured.out == ""
        assert captured.err == ("tpee-ompl library build: error: pair 2->1 (worker process killed by SIGKILL, retry "
                                "in a fresh process killed by SIGKILL) lost: no library built (a library needs "
                                "every pair)\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["kills", "lib.npz"][:3 - times]
    assert mp.active_children() == []


def test_sigterm_during_a_parallel_build_exits_130_leaving_no_worker_and_no_file(tmp_path, monkeypatch,
                                                                                  capsys) -> None:
    """The build's pairs run in processes of their own: ``kill PID`` of the build must end them all."""
    import multiprocessing as mp

    from helpers.library_killers import arm

    arm(monkeypatch, tmp_path / "kills", pair=(1, 2), whom="build")
    out = tmp_path / "lib.npz"
    assert main([*_QUICK_PARALLEL_BUILD, "--library", str(out)]) == 130
    assert capsys.readouterr().err == "tpee-ompl library build: interrupted\n"
    assert not out.exists() and mp.active_children() == []
