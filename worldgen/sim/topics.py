"""A Gazebo topic subscriber kept alive while the world steps: every message in the order it came::

    with gz.subscribe("/scan") as scans:      # before the world moves: the sensor renders on schedule
        gz.step(1000)
        scans.wait(1, step=50)                 # steps until at least one message came; the messages so far
        latest = scans.messages()[-1]

Why a subscriber that stays: a rendering sensor renders only while something subscribes to it, and
ign-sensors 6 moves its next render time forward by one period per render, never to "now". A subscriber
that appears after the world ran without one finds the sensor seconds behind: Gazebo renders it again
and again at the one paused time until it has caught up, and a step asked for during that burst can
deadlock Fortress 6.18's Sensors system (docs/gazebo.md, measured here). Subscribed before the world
moves, the sensor never falls behind.
"""

from __future__ import annotations

import subprocess
import tempfile
import time
from pathlib import Path
from typing import Callable

from worldgen.sim.procs import stop_group

__all__ = ["Subscription"]


class Subscription:
    """A subscriber process (``ign topic -e -t <topic>``) printing into a file until :meth:`close`; a context
    manager. ``step(n)`` advances the world ``n`` iterations (:meth:`~worldgen.sim.gazebo.GazeboServer.step`);
    ``parse`` turns complete messages' text into messages; ``error`` is the exception a time-out raises.
    """

    def __init__(self, topic: str, command: list[str], env: dict[str, str], step: Callable[[int], object],
                 parse: Callable[[str], list[dict]], error: type[Exception]):
        self.topic = topic
        self._step, self._parse, self._error = step, parse, error
        self._folder = tempfile.TemporaryDirectory(prefix="worldgen-topic-")
        path = Path(self._folder.name) / "messages.txt"
        # The subscriber appends through a file object of its own: one shared with the reader would share its
        # offset too, and a seek to read would move where the subscriber writes. Its stderr goes elsewhere: the
        # transport prints there what it makes of other processes' discovery ("Unknown message type [8].", sent
        # by a Harmonic tool to a Fortress one), in the middle of a message's text if it shared the file.
        with open(path, "ab") as out, open(path.with_name("stderr.txt"), "ab") as err:
            self._proc: subprocess.Popen | None = subprocess.Popen(
                command, env=env, stdin=subprocess.DEVNULL, stdout=out, stderr=err, start_new_session=True)
        self._reader = open(path, "rb")
        self._read = 0  # bytes of the file parsed into self._got
        self._got: list[dict] = []

    def __enter__(self) -> Subscription:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def messages(self) -> list[dict]:
        """Every complete message so far, oldest first. ``ign topic -e`` ends each message with a blank line:
        what follows the last one is a message still being written (or cut short by :meth:`close`)."""
        if not self._reader.closed:
            self._reader.seek(self._read)
            new = self._reader.read()
            cut = new.rfind(b"\n\n")
            if cut >= 0:  # parsed once: a subscriber to a sensor gathers megabytes over a long run
                self._got += self._parse(new[:cut + 1].decode("utf-8", errors="replace"))
                self._read += cut + 2
        return list(self._got)

    def wait(self, count: int, step: int = 0, timeout: float = 60.0,
             where: Callable[[dict], bool] | None = None) -> list[dict]:
        """The messages so far (those ``where`` accepts, if given) once there are at least ``count``; ``step`` > 0
        steps the world that many iterations at a time meanwhile (a sensor publishes only while time moves)."""
        deadline = time.monotonic() + timeout
        while True:
            got = [m for m in self.messages() if where is None or where(m)]
            if len(got) >= count:
                return got
            if time.monotonic() > deadline:
                raise self._error(f"{len(got)} of {count} message(s) on {self.topic} within {timeout:.0f} s"
                                  + (" of stepping" if step else ""))
            if step:
                self._step(step)
            else:
                time.sleep(0.05)

    def close(self) -> list[dict]:
        """Stop the subscriber; every message it received."""
        if self._proc is not None:
            stop_group(self._proc, grace=0.5)
            self._proc = None
            got = self.messages()
            self._reader.close()
            self._folder.cleanup()
            return got
        return self.messages()
