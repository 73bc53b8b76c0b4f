"""One line of progress on a terminal while a request runs: what it is doing, updated in place on stderr.

The library never writes to the terminal: long requests log what they are doing to the logger
:data:`LOGGER` (a level request its draws, ``worldgen.generate`` the attempt under way one level below,
``worldgen check`` its stages), which is silent unless someone listens. :func:`shown` listens while a
command runs, and only when stderr is a terminal: from :data:`AFTER` seconds on it keeps one line up to
date (the request's latest message, the attempt's after it, the time so far), redrawn as a message comes
(at most once a :data:`TICK`) and every :data:`TICK` s even when none comes, and wipes it before any result
is printed and at the end.
Piped or redirected, nothing is written. ``WORLDGEN_PROGRESS_AFTER`` (seconds) overrides :data:`AFTER`.
"""

from __future__ import annotations

import logging
import os
import shutil
import sys
import threading
import time
from contextlib import contextmanager
from typing import Callable, Iterator, Optional, TextIO

import click

__all__ = ["LOGGER", "AFTER", "TICK", "shown"]

#: The logger long requests report to; its child ``.attempt`` carries the attempt under way.
LOGGER = "worldgen.progress"
#: Seconds a request runs before its line appears (a quick request shows nothing).
AFTER = 2.0
#: Seconds between two redraws.
TICK = 0.25


class _Line(logging.Handler):
    """Keeps the latest request and attempt messages, and draws them as one line from ``after`` s on."""

    def __init__(self, stream: TextIO, after: float):
        super().__init__(logging.INFO)
        self.stream, self.after, self.start = stream, after, time.monotonic()
        self.request, self.attempt, self.drawn, self.last = "", "", False, -TICK
        self.guard, self.stop = threading.Lock(), threading.Event()  # not self.lock: logging.Handler has its own
        self.thread = threading.Thread(target=self._run, name="worldgen-progress", daemon=True)

    def emit(self, record: logging.LogRecord) -> None:
        text = record.getMessage()
        with self.guard:
            if record.name == LOGGER:
                self.request, self.attempt = text, ""
            else:
                self.attempt = text
            fresh = time.monotonic() - self.last >= TICK
        if fresh:  # a new stage shows at once (at most one redraw a tick), not only at the next tick
            self.draw()

    def _run(self) -> None:
        while not self.stop.wait(TICK):
            self.draw()

    def draw(self) -> None:
        elapsed = time.monotonic() - self.start
        with self.guard:
            if elapsed < self.after or not (self.request or self.attempt):
                return
            # Under a request's line, the attempt's own "generator seed N: " prefix (the draw's seed) is left out.
            attempt = self.attempt.split(": ", 1)[-1] if self.request else self.attempt
            text = f"{' | '.join(p for p in (self.request, attempt) if p)} [{elapsed:.0f} s]"
            width = shutil.get_terminal_size((100, 24)).columns
            self.stream.write("\r" + text[:max(width - 1, 20)] + "\x1b[K")
            self.stream.flush()
            self.drawn, self.last = True, time.monotonic()

    def clear(self) -> None:
        """Wipes the line (at the end)."""
        with self.guard:
            self._wipe()

    def echo(self, text: str) -> None:
        """Prints a result line on stdout, the progress line wiped first (no redraw can come between)."""
        with self.guard:
            self._wipe()
            click.echo(text)

    def _wipe(self) -> None:
        if self.drawn:
            self.stream.write("\r\x1b[K")
            self.stream.flush()
            self.drawn = False


@contextmanager
def shown(stream: Optional[TextIO] = None) -> Iterator[Callable[[str], None]]:
    """Shows the progress line on ``stream`` (stderr) while the block runs, when it is a terminal; yields the
    function that prints a result line (``click.echo``, the progress line wiped first)."""
    stream = sys.stderr if stream is None else stream
    if not _is_terminal(stream):
        yield click.echo
        return
    line = _Line(stream, _after())
    logger = logging.getLogger(LOGGER)
    old_level, old_propagate = logger.level, logger.propagate
    logger.addHandler(line)
    logger.setLevel(logging.INFO)
    logger.propagate = False  # the progress is for this line, not for whatever else logs
    line.thread.start()
    try:
        yield line.echo
    finally:
        line.stop.set()
        line.thread.join()
        line.clear()
        logger.removeHandler(line)
        logger.setLevel(old_level)
        logger.propagate = old_propagate


def _is_terminal(stream: TextIO) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # a closed or unusual stream: never a terminal
        return False


def _after() -> float:
    text = os.environ.get("WORLDGEN_PROGRESS_AFTER")
    try:
        return max(0.0, float(text)) if text else AFTER
    except ValueError:
        return AFTER
