"""Experiment outputs are never overwritten: :func:`tpee_ompl.bench.campaign.new_output_stem`."""

from __future__ import annotations

from tpee_ompl.bench.campaign import new_output_stem


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
