"""The command kind of system under test: a program run per world and task, without a shell, that leaves a
rosbag2 bag at ``{bag}`` (:mod:`worldgen.campaign.systems`). Its output goes to ``workdir/logs/<run>.log``;
past its timeout its whole process group is stopped; whatever it leaves running when it exits is killed."""

from __future__ import annotations

import math
import os
import shlex
import shutil
import signal
import string
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Optional

from worldgen.campaign.judging import Outcome, bag_of, judged, unjudged
from worldgen.errors import ParameterError, quoted

__all__ = ["CommandSystem", "PLACEHOLDERS", "DEFAULT_TIMEOUT", "check_template", "check_timeout"]

#: What a command template may say, each filled in per run.
PLACEHOLDERS = ("world", "task", "run", "bag")
#: Seconds a command may run before its process group is killed.
DEFAULT_TIMEOUT = 600.0
#: Seconds between asking a timed-out command's processes to stop and killing them.
_GRACE = 5.0


def check_template(template: Any) -> list[str]:
    """The template's words, each checked to fill in; a one-line ParameterError otherwise."""
    if not isinstance(template, str) or not template.strip():
        raise ParameterError(f"system.command must be a command line with {{bag}} in it, got {quoted(template)}")
    try:
        words = shlex.split(template)
    except ValueError as exc:
        raise ParameterError(f"system.command cannot be split into words ({exc}): {quoted(template)}") from None
    named = set()
    for word in words:
        try:
            fields = [f for _, f, _, _ in string.Formatter().parse(word) if f is not None]
        except ValueError as exc:
            raise ParameterError(f"system.command: {exc} in {word!r} (write a literal brace as {{{{ or }}}})") from None
        for f in fields:
            if f not in PLACEHOLDERS:
                raise ParameterError(f"system.command: unknown placeholder {{{f}}}; known: "
                                     f"{', '.join('{' + p + '}' for p in PLACEHOLDERS)}")
            named.add(f)
    if "bag" not in named:
        raise ParameterError(f"system.command must say where the run's bag goes with {{bag}}, got {quoted(template)}")
    if "{" not in words[0] and shutil.which(words[0]) is None:
        raise ParameterError(f"system.command: {words[0]!r} is not a program that can be run (not on PATH, "
                             "or not executable)")
    return words


def check_timeout(value: Any) -> float:
    """The command's timeout in seconds; a one-line ParameterError unless a finite number > 0."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
        raise ParameterError(f"system.timeout must be a number of seconds > 0, got {quoted(value)}")
    return float(value)


def _stop(proc: subprocess.Popen) -> None:
    """Stop the command's whole process group: asked first, then killed after :data:`_GRACE` s."""
    for sig, wait in ((signal.SIGTERM, _GRACE), (signal.SIGKILL, None)):
        try:
            os.killpg(proc.pid, sig)
        except ProcessLookupError:
            return
        try:
            proc.wait(timeout=wait)
            if sig == signal.SIGTERM:  # the leader is gone; children left in its group go now
                os.killpg(proc.pid, signal.SIGKILL)
            return
        except ProcessLookupError:
            return
        except subprocess.TimeoutExpired:
            continue


@dataclass(frozen=True)
class CommandSystem:
    """A program per world and task that leaves a rosbag2 bag at ``{bag}``; ``timeout`` s at most."""

    command: str
    timeout: float = DEFAULT_TIMEOUT
    criteria: Optional[dict] = field(default=None, hash=False)
    kind: str = "command"

    def run(self, world: Path, task: str, run: str, workdir: Path) -> Outcome:
        started = time.perf_counter()
        bag = bag_of(world, task, run, workdir)
        values = {"world": str(Path(world).resolve()), "task": task, "run": run, "bag": str(bag.resolve())}
        args = [word.format(**values) for word in shlex.split(self.command)]
        logs = Path(workdir) / "logs"
        logs.mkdir(parents=True, exist_ok=True)
        with open(logs / f"{bag.name}.log", "wb") as log:
            try:
                proc = subprocess.Popen(args, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                                        start_new_session=True)
            except OSError as exc:
                return unjudged(f"cannot start {args[0]!r}: {exc.strerror or exc}", started)
            try:
                status = proc.wait(timeout=self.timeout)
            except subprocess.TimeoutExpired:
                _stop(proc)
                return unjudged(f"timed out after {self.timeout:g} s", started)
            finally:
                if proc.returncode is None:
                    _stop(proc)
        try:  # what the command started and left behind dies with its run
            os.killpg(proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
        if status < 0:
            return unjudged(f"killed by signal {-status}", started)
        if status:
            return unjudged(f"exit status {status}", started)
        return judged(bag, Path(world), task, run, self.criteria, started)
