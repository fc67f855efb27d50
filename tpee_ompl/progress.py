"""Progress bars on stderr with the time left, readable in a terminal and in a log file.

Every long-running command (``bench``, ``library build``, ``track``, ``animate``, ``workspace``) shows its progress
through :func:`progress_bar`.  In a terminal it is tqdm's bar, redrawn in place.  When stderr is not a terminal (a
log file, a pipe, CI), a redrawn bar would be one line of carriage returns with hundreds of states in it; there the
progress goes out as plain lines, at most one every :data:`LOG_INTERVAL` seconds, and one at the end.
"""

from __future__ import annotations

import sys
from typing import Any, TextIO

from tqdm import tqdm

__all__ = ["LOG_INTERVAL", "progress_bar"]

LOG_INTERVAL = 30.0
"""Seconds between two progress lines when stderr is not a terminal."""

_LOG_FORMAT = "{desc}: {n_fmt}/{total_fmt} {unit} ({percentage:.0f} %), {elapsed} elapsed, {remaining} left{postfix}"
_LOG_FORMAT_SHARE = "{desc}: {percentage:.0f} %, {elapsed} elapsed, {remaining} left{postfix}"
"""(A bar counting estimated units of work rather than things: the share done only.)"""
_LOG_FORMAT_OPEN = "{desc}: {n_fmt} {unit}, {elapsed} elapsed{postfix}"
"""(A bar without a total: how much is done, no time left.)"""


class _Lines:
    """A stream for tqdm that writes each state of the bar as a line of its own (no carriage returns)."""

    def __init__(self, stream: TextIO) -> None:
        self._stream = stream

    @property
    def encoding(self) -> str | None:
        return getattr(self._stream, "encoding", None)

    def write(self, text: str) -> int:
        line = text.replace("\r", "").strip()
        if line:
            self._stream.write(line + "\n")
        return len(text)

    def flush(self) -> None:
        self._stream.flush()


class _LogBar(tqdm):
    """tqdm writing to a log: its first line as soon as a terminal's bar would show (after ``delay``), the next ones
    at most every :data:`LOG_INTERVAL` s (tqdm's own interval would hold the first line back as long)."""

    def display(self, *args: Any, **kwargs: Any) -> Any:
        shown = super().display(*args, **kwargs)
        self.mininterval = LOG_INTERVAL
        return shown


def _is_terminal(stream: TextIO) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # no isatty, or a closed stream
        return False


def progress_bar(iterable: Any = None, *, total: float | None = None, desc: str, unit: str = "it",
                 enabled: bool = True, delay: float = 0.0, bar_format: str | None = None, counts: bool = True,
                 stream: TextIO | None = None) -> tqdm:
    """A tqdm progress bar on ``stream`` (default stderr): in a terminal redrawn in place (``bar_format`` as tqdm
    takes it), elsewhere a line at most every :data:`LOG_INTERVAL` s and one when it closes.  ``enabled=False``:
    a bar that shows nothing (the commands' ``--no-progress``); ``delay``: seconds before it first shows;
    ``counts=False``: the units are estimates of work (not things done), so a log line gives the share done only."""
    out = sys.stderr if stream is None else stream
    if not enabled or _is_terminal(out):
        return tqdm(iterable, total=total, desc=desc, unit=unit, disable=not enabled, delay=delay,
                    bar_format=bar_format, file=out)
    known = total is not None or hasattr(iterable, "__len__")
    # miniters=1: every update asks the clock (tqdm's adaptive count, set from a 30-s interval, held lines back until
    # its monitor thread redrew the bar, which then printed two lines at once)
    return _LogBar(iterable, total=total, desc=desc, unit=unit, delay=delay, file=_Lines(out), ascii=True,
                   mininterval=0.0, miniters=1,
                   bar_format=(_LOG_FORMAT if counts else _LOG_FORMAT_SHARE) if known else _LOG_FORMAT_OPEN)
