"""The tpee-ompl entry point: argument errors, one-line errors with exit code 2, the command groups wired in."""

from __future__ import annotations

import pytest
from helpers.cli_queries import start_goal_args

from tpee_ompl.cli.main import main


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["plan", "--from", "1", "--to", "9"], "unknown sector 9"),
        (["plan", "--from", "1", "--to", "4", "--planner", "magic"], "invalid choice"),
        (["plan", "--from", "1", "--to", "4", "--start", "nan", "0", "0", "0", "--goal", "0", "1", "0", "0"],
         "not a finite number"),
        (["plan", "--from", "1", "--to", "4", "--samples", "0"], "positive integer"),
    ],
)
def test_bad_arguments_exit_non_zero_with_one_line(capsys, argv, message):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code != 0
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


@pytest.mark.parametrize(
    ("argv", "said_by"),
    [
        (["--bogus"], "tpee-ompl: "),
        (["-v", "--bogus"], "tpee-ompl: "),
        (["plan", "--from", "1", "--to", "4", "--bogus"], "tpee-ompl plan: "),
        (["library", "stats", "--bogus", "x"], "tpee-ompl library stats: "),
    ],
)
def test_an_unknown_option_is_named_by_the_command_it_was_given_to(capsys, argv, said_by):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith(said_by + "error: unrecognized arguments: --bogus") and err.count("\n") == 1


def test_version_is_printed(capsys):
    from tpee_ompl import __version__

    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0 and capsys.readouterr().out.strip() == f"tpee-ompl {__version__}"


def test_missing_urdf_is_one_line_on_stderr(capsys, tmp_path):
    argv = ["plan", "--from", "1", "--to", "4", *start_goal_args(), "--urdf", str(tmp_path / "missing.urdf")]
    assert main(argv) == 2
    assert "URDF file not found" in capsys.readouterr().err


def test_bench_help_shows_an_example(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["bench", "--help"])
    assert exc.value.code == 0
    assert "example:" in capsys.readouterr().out


def test_library_query_without_a_library_file_is_one_line(capsys, tmp_path):
    assert main(["library", "stats", "--library", str(tmp_path / "none.npz")]) == 2
    err = capsys.readouterr().err
    assert "not found" in err and err.count("\n") == 1 and err.startswith("tpee-ompl library stats: error:")


def test_library_query_index_without_a_query_set_is_a_usage_error(capsys):
    assert main(["library", "query", "--index", "3", "--from", "1", "--to", "2", "--start", "0", "0", "0", "0",
                 "--goal", "0", "0", "0", "0"]) == 2
    assert "--index picks a query of --query-set" in capsys.readouterr().err


def _raising(exc: BaseException):
    def command(args):
        raise exc
    return command


@pytest.mark.parametrize(("exc", "code", "text"), [
    (TypeError("'NoneType' object is not subscriptable"), 1, "unexpected TypeError"),
    (IndexError("index 0 is out of bounds"), 1, "unexpected IndexError"),
    (RuntimeError("planner failed\non two lines"), 1, "planner failed on two lines"),
    (ValueError("damaged file x.npz"), 1, "damaged file x.npz"),
    (BrokenPipeError(32, "Broken pipe"), 1, "Broken pipe"),  # another pipe than standard output's
])
def test_any_exception_at_run_time_is_one_line_with_exit_code_1(monkeypatch, capsys, exc, code, text):
    import tpee_ompl.cli.plan as plan

    monkeypatch.setattr(plan, "cmd_aim", _raising(exc))
    assert main(["aim", "--target", "5", "2", "1.5"]) == code
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and text in err and "Traceback" not in err


def test_verbose_adds_the_traceback_of_an_unexpected_error(monkeypatch, capsys):
    import tpee_ompl.cli.plan as plan

    monkeypatch.setattr(plan, "cmd_aim", _raising(TypeError("boom")))
    assert main(["-v", "aim", "--target", "5", "2", "1.5"]) == 1
    err = capsys.readouterr().err
    assert "Traceback" in err and err.strip().splitlines()[-1].endswith("(run with -v for the traceback)")


def test_sigterm_ends_any_command_as_ctrl_c_does(monkeypatch, capsys):
    """``kill`` (or a scheduler) gets the cleanup of Ctrl-C in every command, not only in ``bench``: exit 130."""
    import os
    import signal

    import tpee_ompl.cli.plan as plan

    def killed(args):
        os.kill(os.getpid(), signal.SIGTERM)
        for _ in range(10_000):  # the handler runs between bytecodes
            pass
        raise AssertionError("SIGTERM did not interrupt")

    before = signal.getsignal(signal.SIGTERM)
    monkeypatch.setattr(plan, "cmd_aim", killed)
    assert main(["aim", "--target", "5", "2", "1.5"]) == 130
    assert "interrupted" in capsys.readouterr().err
    assert signal.getsignal(signal.SIGTERM) == before


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")  # Python's "Exception ignored"
@pytest.mark.parametrize("then", ["returns", "raises ImportError"])
def test_an_interrupt_python_dropped_or_turned_into_another_error_still_exits_130(monkeypatch, capsys, then):
    """A signal whose KeyboardInterrupt lands in a weakref callback (matplotlib's, while plots are drawn) is dropped
    by Python, and one that stops an import can come back as an ImportError: both used to end with 0 or 1."""
    from helpers.interrupts import interrupt_in_a_weakref_callback

    import tpee_ompl.cli.plan as plan

    def command(args):
        interrupt_in_a_weakref_callback()
        if then == "raises ImportError":
            raise ImportError("initialization failed")
        return 0

    monkeypatch.setattr(plan, "cmd_aim", command)
    assert main(["aim", "--target", "5", "2", "1.5"]) == 130
    assert capsys.readouterr().err.strip().endswith("tpee-ompl aim: interrupted")


@pytest.mark.parametrize("value", ["-1e6", "-1.5E+2", "-.5e-1", "-3"])
def test_negative_numbers_in_any_notation_are_values_not_options(value):
    from tpee_ompl.cli.main import get_argument_parser

    args = get_argument_parser().parse_args(["aim", "--target", "5", value, "1.5"])
    assert args.target[1] == float(value)


def test_output_into_a_closed_pipe_ends_quietly_with_sigpipes_code():
    import os
    import subprocess
    import sys

    r, w = os.pipe()
    os.close(r)  # the reader went away before the first line (``| head -0``)
    try:
        proc = subprocess.run([sys.executable, "-c", "import sys; from tpee_ompl.cli import main; sys.exit(main())",
                               "bench", "--list-problems"], stdout=w, stderr=subprocess.PIPE, text=True, timeout=120)
    finally:
        os.close(w)
    assert proc.returncode == 141 and proc.stderr == ""


@pytest.mark.parametrize("signal_at_import", ["raise KeyboardInterrupt", "os.kill(os.getpid(), signal.SIGTERM)",
                                              "os.kill(os.getpid(), signal.SIGINT)",
                                              "assert {signal.SIGINT, signal.SIGTERM} <= "
                                              "signal.pthread_sigmask(signal.SIG_BLOCK, []); raise KeyboardInterrupt"])
def test_an_interrupt_while_the_command_line_loads_ends_it_with_130_and_one_line(signal_at_import):
    """Ctrl-C in the first 0.3 s (OMPL, Pinocchio and Coal loading) used to print the import's traceback, and SIGTERM
    ended the process without a word (exit 143: the command's own handler was not on yet).  Both signals are now held
    while the modules load (one raised inside a compiled module's initialisation aborted the process: SIGINT
    and SIGTERM sent to `tpee-ompl track` at 0.20-0.35 s by a scratch probe: 4 aborts in 80) and delivered after.  Simulated at the import of pinocchio, which the
    command line's modules load; the last case checks that both signals are held there."""
    import subprocess
    import sys

    code = ("import builtins, os, signal, sys\n"
            "real = builtins.__import__\n"
            "def interrupted(name, *a, **k):\n"
            "    if name == 'pinocchio':\n"
            f"        {signal_at_import}\n"
            "    return real(name, *a, **k)\n"
            "builtins.__import__ = interrupted\n"
            "from tpee_ompl._launch import main\n"
            "sys.exit(main())\n")
    proc = subprocess.run([sys.executable, "-c", code, "plan", "--from", "1", "--to", "4"], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 130 and proc.stderr == "tpee-ompl: interrupted\n" and proc.stdout == ""


def test_python_dash_m_tpee_ompl_is_the_command_line():
    import subprocess
    import sys

    proc = subprocess.run([sys.executable, "-m", "tpee_ompl", "aim", "--target", "5", "2", "1.5"], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0 and proc.stdout.strip() and proc.stderr == ""
    bad = subprocess.run([sys.executable, "-m", "tpee_ompl", "aim"], capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and bad.stderr.startswith("tpee-ompl aim: error:")


def test_the_command_line_runs_with_docstrings_stripped_by_python_dash_oo():
    """Under ``python -OO`` the parser read its description from a docstring that is None: every command failed."""
    import subprocess
    import sys

    proc = subprocess.run([sys.executable, "-OO", "-m", "tpee_ompl", "aim", "--target", "5", "2", "1.5"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and proc.stdout.strip() and proc.stderr == ""


def test_an_interrupt_while_the_command_cleans_up_after_its_work_ends_with_130(monkeypatch, capsys):
    """The last clean-up (a garbage collection) ran after the interrupt handling: Ctrl-C there printed a traceback
    or was lost (exit 0)."""
    import importlib

    cli_main = importlib.import_module("tpee_ompl.cli.main")  # the module (the package exports its main())

    def interrupted() -> int:
        raise KeyboardInterrupt

    monkeypatch.setattr(cli_main.gc, "collect", interrupted)
    assert cli_main.main(["aim", "--target", "5", "2", "1.5"]) == 130
    assert capsys.readouterr().err.strip().endswith("interrupted")


def test_a_model_given_without_its_srdf_whose_every_configuration_collides_is_warned_about(capsys, caplog):
    """A helper's ``aim --urdf <the packaged URDF>`` (no ``--srdf``) said "collision-free: False" for a free pose,
    and ``workspace`` drew "0 of 200 configurations collision-free", without a word on why."""
    from tpee_ompl.resources import model_file

    urdf, srdf = model_file("wearer_arm.urdf"), model_file("wearer_arm.srdf")
    main(["aim", "--target", "5", "2", "1.5", "--urdf", str(urdf)])
    assert "without --srdf no collision pair is disabled" in caplog.text
    caplog.clear()
    assert main(["aim", "--target", "5", "2", "1.5", "--urdf", str(urdf), "--srdf", str(srdf)]) == 0
    assert "collision pair" not in caplog.text


@pytest.mark.parametrize("argv", [["aim", "--target", "5", "2", "1.5"], ["aim", "--target", "5", "2", "1.5", "--json"],
                                  ["plan", "--from", "1", "--to", "4", "--planner", "rrtconnect", "--time", "1",
                                   "--json"]])
def test_standard_output_on_a_full_device_is_named_in_one_line_with_exit_1(argv):
    """``tpee-ompl plan ... > /dev/full`` said "error: [Errno 28] No space left on device", not what could not be
    written."""
    import os
    import subprocess
    import sys

    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full here")
    with open("/dev/full", "w") as full:
        proc = subprocess.run([sys.executable, "-m", "tpee_ompl", *argv], stdout=full, stderr=subprocess.PIPE,
                              text=True, timeout=120)
    assert (proc.returncode, proc.stderr) == (1, f"tpee-ompl {argv[0]}: error: cannot write to standard output: No "
                                                 "space left on device\n")


def test_a_failing_write_of_a_long_output_names_standard_output_too(monkeypatch, capsys):
    """The output that fills the buffer fails inside the command's print, not at the final flush."""
    import errno
    import io
    import os
    import sys

    class Full(io.StringIO):
        def write(self, text: str) -> int:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(sys, "stdout", Full())
    assert main(["aim", "--target", "5", "2", "1.5"]) == 1
    assert capsys.readouterr().err == "tpee-ompl aim: error: cannot write to standard output: No space left on device\n"
    assert isinstance(sys.stdout, Full)  # put back
