"""Issue 19's table of bad input: every case is refused as a user sees it (``python -m tpee_ompl.cli``).

A refusal (:func:`helpers.cli_run.assert_refused`): exit status 2 for a usage error (found from the
arguments before any work) or 1 for a runtime error (found in a file's content while working), one
line on stderr naming the argument or the file, no traceback; and (:func:`helpers.cli_run.snapshot`)
nothing created in the working folder and no existing file changed.  Every refusal comes before any
planning, so each case takes about the interpreter's start-up time.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from helpers.cli_queries import GOAL, START
from helpers.cli_run import assert_refused, run_cli, snapshot
from helpers.hostile_files import (
    LIBRARY_DEFECTS,
    other_model_query_file,
    truncated_library_file,
    write_library_file,
    write_path_file,
    write_query_file,
    QUERY_DEFECTS,
)

pytestmark = pytest.mark.slow  # ~30 s of subprocesses; CI and `make test` run it

SG = ["--start", *map(str, START), "--goal", *map(str, GOAL)]
"""A valid --start/--goal (sector 1 preset -> sector 4 preset)."""
IN_COLLISION = ["-0.085", "0.299", "-0.799", "-1.202"]
"""A configuration inside the wearer."""
ISSUE_LIBRARY_DEFECTS = ("meta-is-a-list", "unknown-dmp-option", "pairs-is-5", "1-d-waypoints", "nan-weights",
                         "n-candidates-negative", "huge-waypoints", "huge-weights")
ISSUE_QUERY_DEFECTS = ("start-strings", "from-sector-true")

# (case id, arguments, exit code, names the one stderr line must contain).  "{in}" is the folder of
# input files (built once, see `inputs`); relative names are in the working folder, where
# existing.csv, existing.png, existing.gif, existing.npz and the folder adir/ already exist.
USAGE = [
    # plan: seeds, indices, sectors, times, start/goal, model files, query sets
    ("plan-seed-negative", ["plan", "--from", "1", "--to", "4", "--seed", "-3"], "--seed"),
    ("plan-seed-20-digits", ["plan", "--from", "1", "--to", "4", "--seed", "12345678901234567890"], "--seed"),
    ("plan-seed-zero", ["plan", "--from", "1", "--to", "4", "--seed", "0"], "--seed"),
    ("plan-seed-not-a-number", ["plan", "--from", "1", "--to", "4", "--seed", "1.5"], "--seed"),
    ("plan-query-index-negative", ["plan", "--from", "1", "--to", "4", "--query-index", "-1"], "--query-index"),
    ("plan-query-index-out-of-range", ["plan", "--from", "1", "--to", "4", "--query-index", "10"], "--query-index"),
    ("plan-same-sectors", ["plan", "--from", "2", "--to", "2"], "--from"),
    ("plan-sector-5", ["plan", "--from", "1", "--to", "5"], "--to"),
    ("plan-time-nan", ["plan", "--from", "1", "--to", "4", "--time", "nan"], "--time"),
    ("plan-time-negative", ["plan", "--from", "1", "--to", "4", "--time", "-1"], "--time"),
    ("plan-time-word", ["plan", "--from", "1", "--to", "4", "--time", "soon"], "--time"),
    ("plan-samples-zero", ["plan", "--from", "1", "--to", "4", "--samples", "0"], "--samples"),
    ("plan-samples-huge", ["plan", "--from", "1", "--to", "4", "--samples", "10000000000"], "--samples"),
    ("plan-start-without-goal", ["plan", "--from", "1", "--to", "4", "--start", "0", "0", "0", "0"], "--start"),
    ("plan-start-in-collision", ["plan", "--from", "1", "--to", "4", "--start", *IN_COLLISION,
                                 "--goal", *map(str, GOAL)], "--start"),
    ("plan-start-outside-limits", ["plan", "--from", "1", "--to", "4", "--start", "9", "0", "0", "0",
                                   "--goal", *map(str, GOAL)], "--start"),
    ("plan-urdf-missing", ["plan", "--from", "1", "--to", "4", *SG, "--urdf", "missing.urdf"], "--urdf"),
    ("plan-urdf-a-folder", ["plan", "--from", "1", "--to", "4", *SG, "--urdf", "adir"], "--urdf"),
    ("plan-srdf-without-urdf", ["plan", "--from", "1", "--to", "4", *SG, "--srdf", "x.srdf"], "--srdf"),
    ("plan-queries-unknown", ["plan", "--from", "1", "--to", "4", "--queries", "nope"], "--queries"),
    ("plan-planner-unknown", ["plan", "--from", "1", "--to", "4", "--planner", "Nope"], "--planner"),
    # track: outputs, sizes, seeds, library
    ("track-output-a-folder", ["track", "--duration", "1", "-o", "adir"], "--output"),
    ("track-output-exists", ["track", "--duration", "1", "-o", "existing.csv"], "--output"),
    ("track-exabytes", ["track", "--duration", "1e9", "--rate", "1e9"], "--duration"),
    ("track-samples-with-the-default-planner", ["track", "--duration", "1", "--samples", "5"], "--samples"),
    ("track-beyond-the-trackers-clock", ["track", "--duration", "2e10", "--rate", "1e-9"], "--duration"),
    ("track-rate-inf", ["track", "--rate", "inf"], "--rate"),
    ("track-duration-zero", ["track", "--duration", "0"], "--duration"),
    ("track-seed-zero", ["track", "--seed", "0"], "--seed"),
    ("track-library-missing", ["track", "--planner", "library", "--library", "missing.npz"], "--library"),
    # show / animate / workspace / view: outputs, counts, configurations
    ("show-output-a-folder", ["show", "-o", "adir"], "--output"),
    ("show-output-without-suffix", ["show", "-o", "scene"], "--output"),
    ("show-output-unknown-suffix", ["show", "-o", "scene.xyz"], "--output"),
    ("show-output-exists", ["show", "-o", "existing.png"], "--output"),
    ("show-q-nan", ["show", "--q", "nan", "0", "0", "0", "-o", "s.png"], "--q"),
    ("show-q-three-values", ["show", "--q", "0", "0", "0", "-o", "s.png"], "--q"),
    ("show-q-beyond-any-angle", ["show", "--q", "1e300", "0", "0", "0", "-o", "s.png"], "--q"),
    ("show-target-far", ["show", "--target", "1e300", "0", "0", "-o", "s.png"], "--target"),
    ("animate-path-missing", ["animate", "--path", "missing.json", "-o", "m.gif"], "--path"),
    ("animate-output-not-gif", ["animate", "--path", "missing.json", "-o", "m.txt"], "--output"),
    ("animate-output-exists", ["animate", "--path", "{in}/path_ok.json", "-o", "existing.gif"], "--output"),
    ("animate-frames-one", ["animate", "--path", "{in}/path_ok.json", "--frames", "1", "-o", "m.gif"], "--frames"),
    ("animate-frames-huge", ["animate", "--path", "{in}/path_ok.json", "--frames", "1000000", "-o", "m.gif"],
     "--frames"),
    ("animate-seed-zero", ["animate", "--seed", "0", "-o", "m.gif"], "--seed"),
    ("animate-frames-zero-says-the-range", ["animate", "--path", "{in}/path_ok.json", "--frames", "0", "-o", "m.gif"],
     "[2, 500]"),
    ("animate-path-with-a-planner", ["animate", "--path", "{in}/path_ok.json", "--planner", "rrtconnect", "-o", "m.gif"],
     "--planner would be ignored"),
    ("show-output-pgf-needs-latex", ["show", "-o", "scene.pgf"], "--output"),
    ("animate-path-with-a-time-and-a-seed", ["animate", "--path", "{in}/path_ok.json", "--time", "3", "--seed", "7",
                                             "-o", "m.gif"], "--time --seed would be ignored"),
    ("workspace-samples-beyond-memory", ["workspace", "--samples", "10000000", "-o", "w.png"], "--samples"),
    ("workspace-samples-zero", ["workspace", "--samples", "0", "-o", "w.png"], "--samples"),
    ("workspace-seed-negative", ["workspace", "--seed", "-1", "-o", "w.png"], "--seed"),
    ("workspace-seed-too-big", ["workspace", "--seed", str(2**32), "-o", "w.png"], "--seed"),
    ("workspace-output-exists", ["workspace", "--samples", "10", "-o", "existing.png"], "--output"),
    ("view-q-inf", ["view", "--q", "inf", "0", "0", "0", "--no-browser"], "--q"),
    ("view-urdf-missing", ["view", "--no-browser", "--urdf", "missing.urdf"], "--urdf"),
    # aim
    ("aim-target-inside-the-body", ["aim", "--target", "0", "0", "1.2"], "--target"),
    ("aim-target-far", ["aim", "--target", "1e300", "0", "0"], "--target"),
    ("aim-target-word", ["aim", "--target", "a", "b", "c"], "--target"),
    ("aim-target-two-values", ["aim", "--target", "1", "2"], "--target"),
    ("aim-sector-zero", ["aim", "--target", "5", "2", "1.5", "--sector", "0"], "--sector"),
    ("aim-pan-reference-huge", ["aim", "--target", "5", "2", "1.5", "--pan-reference", "1e300"], "--pan-reference"),
    # library build / query / stats
    ("library-build-over-an-existing-library", ["library", "build", "--pairs", "1-2", "--per-pair", "1",
                                                "--library", "existing.npz"], "--library"),
    ("library-build-into-a-folder", ["library", "build", "--pairs", "1-2", "--library", "adir"], "--library"),
    ("library-build-not-npz", ["library", "build", "--pairs", "1-2", "--library", "lib.txt"], "--library"),
    ("library-build-per-pair-zero", ["library", "build", "--per-pair", "0", "--library", "new.npz"], "--per-pair"),
    ("library-build-workers-zero", ["library", "build", "--workers", "0", "--library", "new.npz"], "--workers"),
    ("library-build-seed-negative", ["library", "build", "--seed", "-1", "--library", "new.npz"], "--seed"),
    ("library-build-timeout-nan", ["library", "build", "--timeout", "nan", "--library", "new.npz"], "--timeout"),
    ("library-build-pair-2-2", ["library", "build", "--pairs", "2-2", "--library", "new.npz"], "--pairs"),
    ("library-query-index-negative", ["library", "query", "--query-set", "planning_necessary", "--index", "-1"],
     "--index"),
    ("library-query-index-out-of-range", ["library", "query", "--query-set", "planning_necessary",
                                          "--index", "120"], "--index"),
    ("library-query-set-unknown", ["library", "query", "--query-set", "nope"], "--query-set"),
    ("library-query-set-and-start", ["library", "query", "--query-set", "planning_necessary", "--from", "1"],
     "--from"),
    ("library-query-same-sectors", ["library", "query", "--from", "1", "--to", "1", *SG], "--from"),
    ("library-query-missing-goal", ["library", "query", "--from", "1", "--to", "4", "--start", *map(str, START)],
     "--goal"),
    ("library-query-start-outside-limits", ["library", "query", "--from", "1", "--to", "4", "--start", "9", "0",
                                            "0", "0", "--goal", *map(str, GOAL)], "--start"),
    ("library-query-start-in-collision", ["library", "query", "--from", "1", "--to", "4", "--start", *IN_COLLISION,
                                          "--goal", *map(str, GOAL)], "--start"),
    ("library-query-start-nan", ["library", "query", "--from", "1", "--to", "4", "--start", "nan", "0", "0", "0",
                                 "--goal", *map(str, GOAL)], "--start"),
    ("library-query-library-missing", ["library", "query", "--library", "missing.npz", "--query-set",
                                       "planning_necessary"], "--library"),
    ("library-stats-library-a-folder", ["library", "stats", "--library", "adir"], "--library"),
    ("library-stats-library-missing", ["library", "stats", "--library", "missing.npz"], "make library"),
    ("no-command", [], "COMMAND"),
    # found by a helper's probe (2026-11-26): planners that count no iterations, empty names, files that are
    # not regular files, duplicate or unbounded build settings, a target the sector's arm cannot aim at
    ("plan-samples-for-a-planner-without-iterations", ["plan", "--from", "1", "--to", "4", "--planner", "aorrtc",
                                                       "--samples", "50"], "--samples"),
    ("animate-samples-for-a-planner-without-iterations", ["animate", "--from", "1", "--to", "4", "--planner",
                                                          "aorrtc", "--samples", "50", "-o", "m.gif"], "--samples"),
    ("track-output-empty", ["track", "--duration", "1", "-o", ""], "--output"),
    ("animate-path-empty-name", ["animate", "--path", "", "-o", "m.gif"], "--path"),
    ("aim-urdf-empty", ["aim", "--target", "5", "2", "1.5", "--urdf", ""], "--urdf"),
    ("track-output-a-link-to-a-fifo", ["track", "--duration", "1", "-o", "link.csv", "--force"], "not a regular file"),
    ("track-output-a-fifo", ["track", "--duration", "1", "-o", "fifo.csv", "--force"], "not a regular file"),
    ("aim-target-too-close-for-the-arm", ["aim", "--target", "-0.3", "0", "1.8"], "--target"),
    ("library-build-pair-twice", ["library", "build", "--pairs", "1-2", "1-2", "--library", "new.npz"], "--pairs"),
    ("library-build-per-pair-huge", ["library", "build", "--per-pair", "100000000", "--library", "new.npz"],
     "--per-pair"),
]
RUNTIME = [
    *((f"library-stats-{d}", ["library", "stats", "--library", f"{{in}}/lib_{d}.npz"], f"lib_{d}.npz")
      for d in ISSUE_LIBRARY_DEFECTS),
    ("library-stats-truncated", ["library", "stats", "--library", "{in}/lib_truncated.npz"], "lib_truncated.npz"),
    ("library-query-nan-weights", ["library", "query", "--library", "{in}/lib_nan-weights.npz", "--query-set",
                                   "planning_necessary"], "p12_fwd_weights"),
    ("track-library-meta-is-a-list", ["track", "--planner", "library", "--library", "{in}/lib_meta-is-a-list.npz",
                                      "-o", "t.csv"], "lib_meta-is-a-list.npz"),
    *((f"plan-queries-{d}", ["plan", "--from", "1", "--to", "2", "--queries", f"{{in}}/q_{d}.json"], f"q_{d}.json")
      for d in ISSUE_QUERY_DEFECTS),
    ("plan-queries-start-strings-names-start", ["plan", "--from", "1", "--to", "2", "--queries",
                                                "{in}/q_start-strings.json"], "'start'"),
    ("plan-queries-from-sector-true-names-it", ["plan", "--from", "1", "--to", "2", "--queries",
                                                "{in}/q_from-sector-true.json"], "'from_sector'"),
    ("plan-queries-other-model", ["plan", "--from", "1", "--to", "2", "--queries", "{in}/q_other_model.json"],
     "model_hash"),
    ("library-query-set-other-model", ["library", "query", "--query-set", "{in}/q_other_model.json"], "model_hash"),
    ("animate-empty-path", ["animate", "--path", "{in}/path_empty.json", "-o", "m.gif"], "--path"),
    ("animate-one-waypoint", ["animate", "--path", "{in}/path_one.json", "-o", "m.gif"], "at least two waypoints"),
    ("animate-path-of-strings", ["animate", "--path", "{in}/path_strings.json", "-o", "m.gif"], "waypoint 0"),
    ("animate-path-three-values", ["animate", "--path", "{in}/path_short.json", "-o", "m.gif"], "waypoint 1"),
    ("animate-path-not-json", ["animate", "--path", "{in}/path_not_json.json", "-o", "m.gif"], "--path"),
    ("animate-path-outside-the-joint-limits", ["animate", "--path", "{in}/path_huge.json", "-o", "m.gif"], "waypoint 1"),
    ("plan-queries-nested-too-deep", ["plan", "--from", "1", "--to", "4", "--queries", "{in}/deep.json"],
     "deep.json"),
    ("plan-urdf-malformed", ["plan", "--from", "1", "--to", "4", *SG, "--urdf", "{in}/bad.urdf"], "bad.urdf"),
]
CASES = [pytest.param(a, 2, n, id=i) for i, a, n in USAGE] + [pytest.param(a, 1, n, id=i) for i, a, n in RUNTIME]


@pytest.fixture(scope="module")
def inputs(tmp_path_factory) -> Path:
    """The damaged input files the table names as {in}/..."""
    d = tmp_path_factory.mktemp("inputs")
    for name in ISSUE_LIBRARY_DEFECTS:
        write_library_file(d / f"lib_{name}.npz", LIBRARY_DEFECTS[name][0])
    truncated_library_file(d / "lib_truncated.npz")
    for name in ISSUE_QUERY_DEFECTS:
        write_query_file(d / f"q_{name}.json", QUERY_DEFECTS[name][0])
    other_model_query_file(d / "q_other_model.json")
    write_path_file(d / "path_ok.json", [START, GOAL])
    write_path_file(d / "path_empty.json", [])
    write_path_file(d / "path_one.json", [START])
    write_path_file(d / "path_strings.json", [[str(v) for v in START], GOAL])
    write_path_file(d / "path_short.json", [START, GOAL[:3]])
    write_path_file(d / "path_huge.json", [START, [1e300, 0.0, 0.0, 0.0]])
    (d / "path_not_json.json").write_text("{not json")
    (d / "deep.json").write_text("[" * 100_000 + "]" * 100_000)
    (d / "bad.urdf").write_text("<robot name='x'><link name=")
    return d


@pytest.fixture
def workdir(tmp_path: Path) -> Path:
    """A working folder with outputs that must survive: files a command would overwrite, a folder."""
    (tmp_path / "existing.csv").write_text("t,dof1\n0,0\n")
    (tmp_path / "existing.png").write_bytes(b"\x89PNG precious")
    (tmp_path / "existing.gif").write_bytes(b"GIF89a precious")
    write_library_file(tmp_path / "existing.npz")
    (tmp_path / "adir").mkdir()
    (tmp_path / "adir" / "keep.txt").write_text("keep")
    os.mkfifo(tmp_path / "fifo.csv")  # --force must not replace a pipe (or a device) with a file,
    (tmp_path / "link.csv").symlink_to(tmp_path / "fifo.csv")  # nor one a link points to
    return tmp_path


@pytest.mark.parametrize(("argv", "code", "name"), CASES)
def test_bad_input_is_refused_in_one_line_and_changes_nothing(inputs: Path, workdir: Path, argv, code, name):
    argv = [a.replace("{in}", str(inputs)) for a in argv]
    before, inputs_before = snapshot(workdir), snapshot(inputs)
    dirs_before = sorted(p for p in workdir.rglob("*") if p.is_dir())
    proc = run_cli(argv, cwd=workdir)
    assert_refused(proc, code, name)
    assert snapshot(workdir) == before, "the working folder changed"
    assert sorted(p for p in workdir.rglob("*") if p.is_dir()) == dirs_before, "a folder was created"
    assert snapshot(inputs) == inputs_before


def test_the_table_covers_every_command():
    commands = {a[0] for _, a, _ in USAGE + RUNTIME if a} | {" ".join(a[:2]) for _, a, _ in USAGE + RUNTIME
                                                             if a and a[0] == "library"}
    assert {"plan", "track", "show", "animate", "workspace", "view", "aim", "library build", "library query",
            "library stats"} <= commands
