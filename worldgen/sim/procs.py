"""Child processes of a simulator: run a tool with a time limit, stop a process group for certain.

Every child starts in its own session (so its own process group): a time-out or a stop reaches the tool
and whatever it started, and nothing of ours is signalled by mistake.
"""

from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path

__all__ = ["run_tool", "stop_group", "group_members"]


def run_tool(args: list[str], env: dict[str, str], timeout: float, errors: list[str] | None = None) -> str:
    """A tool's stdout + stderr (an argument list, no shell), or its stdout alone with its stderr appended to
    ``errors`` when that list is given; on time-out its whole group is killed, then
    :class:`subprocess.TimeoutExpired` is raised."""
    proc = subprocess.Popen(args, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT if errors is None else subprocess.PIPE, start_new_session=True)
    try:
        out, err = proc.communicate(timeout=timeout)
        if errors is not None:
            errors.append(err.decode("utf-8", errors="replace"))
    except subprocess.TimeoutExpired:
        stop_group(proc, grace=0.5)
        raise
    finally:
        if proc.poll() is None:
            stop_group(proc, grace=0.5)
    return out.decode("utf-8", errors="replace")


def group_members(pgid: int) -> list[int]:
    """Live (not zombie) processes whose process group is ``pgid``, read from /proc."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            text = stat.read_text()
        except OSError:
            continue
        # the command name in parentheses may hold spaces: the fields after its closing parenthesis are fixed
        fields = text[text.rfind(")") + 2:].split()
        if len(fields) > 2 and fields[0] != "Z" and int(fields[2]) == pgid:
            found.append(int(stat.parent.name))
    return found


def _signal_group(pgid: int, sig: int) -> None:
    try:
        os.killpg(pgid, sig)
    except ProcessLookupError:
        pass


def stop_group(proc: subprocess.Popen, grace: float = 3.0) -> int | None:
    """SIGINT then SIGTERM to ``proc``'s group, SIGKILL to what is left after ``grace`` seconds; the exit status."""
    pgid = proc.pid
    for sig in (signal.SIGINT, signal.SIGTERM):
        _signal_group(pgid, sig)
        deadline = time.monotonic() + grace / 2
        while time.monotonic() < deadline and (proc.poll() is None or group_members(pgid)):
            time.sleep(0.05)
    if proc.poll() is None or group_members(pgid):
        _signal_group(pgid, signal.SIGKILL)
    try:
        status = proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        return None
    # A killed grandchild stays listed (not yet a zombie) for a moment while the kernel tears it down.
    deadline = time.monotonic() + 5.0
    while group_members(pgid) and time.monotonic() < deadline:
        time.sleep(0.02)
    return status
