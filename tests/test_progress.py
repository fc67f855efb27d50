"""Progress bars: redrawn in a terminal, plain lines in a log (a campaign's log was one line of carriage returns)."""

from __future__ import annotations

import io

from tpee_ompl.progress import progress_bar


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_progress_off_a_terminal_is_plain_lines_with_the_count_and_the_time_left():
    out = io.StringIO()
    with progress_bar(total=24, desc="seed1 queries", unit="query", stream=out) as bar:
        for _ in range(24):
            bar.update(1)
    text = out.getvalue()
    assert "\r" not in text and text.endswith("\n")
    lines = text.splitlines()
    assert lines[0].startswith("seed1 queries: 0/24 query (0 %)")
    assert lines[-1].startswith("seed1 queries: 24/24 query (100 %)") and "left" in lines[-1]


def test_progress_off_a_terminal_writes_the_first_and_the_last_state_of_a_quick_run_only():
    out = io.StringIO()
    with progress_bar(total=500, desc="pairs", stream=out) as bar:
        for _ in range(500):
            bar.update(1)
    assert len(out.getvalue().splitlines()) == 2  # one line at most every LOG_INTERVAL (30 s) in between


def test_progress_in_a_terminal_is_redrawn_in_place():
    out = _Terminal()
    with progress_bar(total=3, desc="pairs", stream=out) as bar:
        bar.update(3)
    assert "\r" in out.getvalue() and "3/3" in out.getvalue()


def test_a_disabled_progress_bar_writes_nothing_on_or_off_a_terminal():
    for out in (io.StringIO(), _Terminal()):
        with progress_bar(total=3, desc="pairs", enabled=False, stream=out) as bar:
            bar.update(3)
        assert out.getvalue() == ""


def test_a_progress_bar_without_a_total_gives_the_count_only():
    out = io.StringIO()
    for _ in progress_bar(iter(range(7)), desc="track", unit="sample", stream=out):
        pass
    assert out.getvalue().splitlines()[-1].startswith("track: 7 sample,")
    assert "%" not in out.getvalue()


def test_a_bar_of_estimated_work_gives_the_share_done_only():
    out = io.StringIO()
    with progress_bar(total=2.5e6, desc="animate", counts=False, stream=out) as bar:
        bar.set_postfix_str("encoding", refresh=False)
        bar.update(2.5e6)
    last = out.getvalue().splitlines()[-1]
    assert last.startswith("animate: 100 %,") and last.endswith("encoding") and "e+06" not in last


def test_progress_off_a_terminal_writes_a_line_per_interval_while_the_work_goes_on(monkeypatch):
    import time

    import tpee_ompl.progress as progress

    monkeypatch.setattr(progress, "LOG_INTERVAL", 0.05)
    out = io.StringIO()
    t0 = time.perf_counter()
    with progress_bar(total=40, desc="pairs", stream=out) as bar:
        for _ in range(40):
            time.sleep(0.01)
            bar.update(1)
    elapsed = time.perf_counter() - t0
    lines = out.getvalue().splitlines()
    assert 3 <= len(lines) <= 2 + elapsed / 0.05 + 1  # the first, at most one per interval while it ran, the last
    done = [int(line.split("/")[0].split()[-1]) for line in lines]
    assert done == sorted(done) and done[-1] == 40
