"""Result files are never overwritten: :mod:`tpee_ompl.bench.results`."""

from __future__ import annotations

from tpee_ompl.bench.results import format_value, make_results_dir, new_output_stem


def test_existing_results_get_a_new_timestamped_stem(tmp_path) -> None:
    stem = tmp_path / "sub" / "benchmark"
    assert new_output_stem(stem) == stem and stem.parent.is_dir()
    stem.with_suffix(".json").write_text("{}")
    second = new_output_stem(stem)
    assert second != stem and second.name.startswith("benchmark_") and second.parent == stem.parent
    second.with_suffix(".csv").write_text("")
    third = new_output_stem(stem)
    assert third not in (stem, second)
    assert stem.with_suffix(".json").read_text() == "{}"


def test_results_dirs_are_always_new(tmp_path):
    a, b = make_results_dir(tmp_path, "x y"), make_results_dir(tmp_path, "x y")
    assert a != b and a.is_dir() and b.is_dir() and a.name.endswith("_x_y")


def test_values_are_formatted_as_ompl_log_text():
    assert [format_value(v) for v in (None, True, 3, 0.5, float("nan"), float("inf"), "s")] == [
        "", "1", "3", "0.5", "nan", "inf", "s"]


def test_a_json_line_is_never_glued_to_a_last_line_cut_short(tmp_path):
    import json

    from tpee_ompl.bench.results import append_json_line

    path = tmp_path / "tasks.jsonl"
    append_json_line(path, {"qpos": 0})
    path.write_text(path.read_text() + '{"qpos": 1, "lo')  # cut short by something else
    append_json_line(path, {"qpos": 2})
    lines = path.read_text().splitlines()
    assert len(lines) == 3 and json.loads(lines[0]) == {"qpos": 0} and json.loads(lines[2]) == {"qpos": 2}
