"""The progress line: on a terminal (a pseudo-terminal here) a long request keeps one line up to date on
stderr; piped, nothing; the result on stdout is never mixed with it."""

from __future__ import annotations

import os
import pty
import select
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
# Level 7 in a cluttered room, seed 3: nine draws (about 1 s), each reported.
LEVEL = ["generate", "cluttered", "--difficulty", "7/10", "--seed", "3"]

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="pseudo-terminals are POSIX")


def _env(after: str) -> dict:
    env = dict(os.environ, WORLDGEN_PROGRESS_AFTER=after, COLUMNS="200")
    env["PYTHONPATH"] = os.pathsep.join([str(REPO), env.get("PYTHONPATH", "")])
    return env


def _run_on_pty(args, after: str) -> tuple[int, str, str]:
    """(exit status, stdout, what the terminal got on stderr) of the command with stderr on a pty."""
    master, slave = pty.openpty()
    proc = subprocess.Popen([sys.executable, "-m", "worldgen", *map(str, args)], stdout=subprocess.PIPE,
                            stderr=slave, stdin=subprocess.DEVNULL, env=_env(after), cwd=REPO)
    os.close(slave)
    got = b""
    while True:
        ready, _, _ = select.select([master], [], [], 120)
        if not ready:
            proc.kill()
            raise AssertionError("no output for 120 s")
        try:
            chunk = os.read(master, 4096)
        except OSError:  # the child closed the terminal
            break
        if not chunk:
            break
        got += chunk
    out = proc.stdout.read().decode() if proc.stdout else ""
    os.close(master)
    return proc.wait(timeout=120), out, got.decode(errors="replace")


def test_a_long_request_shows_one_line_updated_in_place_on_a_terminal(tmp_path):
    status, out, term = _run_on_pty([*LEVEL, "--out", tmp_path], after="0")
    assert status == 0, term
    assert "\r" in term and "\x1b[K" in term and "\n" not in term.strip("\r\n"), term  # one line, redrawn
    assert "cluttered at level 7/10, seed 3: draw" in term and "of at most 40" in term, term
    assert term.endswith("\r\x1b[K"), term  # wiped at the end
    assert out.count("\n") == 1 and "\x1b" not in out and "\tdraws 9\tattempts" in out, out


def test_nothing_when_stderr_is_piped(tmp_path):
    res = subprocess.run([sys.executable, "-m", "worldgen", *LEVEL, "--out", str(tmp_path)], capture_output=True,
                         text=True, env=_env("0"), cwd=REPO, timeout=120)
    assert res.returncode == 0 and res.stderr == "", res.stderr
    assert "\tdraws 9\t" in res.stdout


def test_a_quick_request_shows_nothing_even_on_a_terminal(tmp_path):
    status, out, term = _run_on_pty(["generate", "minimal", "--out", tmp_path], after="2")
    assert status == 0 and term == "" and "attempts 1" in out, (term, out)


def test_check_says_which_stage_it_is_in(tmp_path):
    subprocess.run([sys.executable, "-m", "worldgen", "generate", "cluttered", "--seed", "1", "--out", str(tmp_path)],
                   check=True, capture_output=True, env=_env("2"), cwd=REPO, timeout=120)
    (folder,) = [p for p in tmp_path.iterdir() if p.is_dir()]
    status, out, term = _run_on_pty(["check", folder], after="0")
    assert status == 0 and out.startswith("OK "), (out, term)
    stages = ("hashes", "schema", "regenerating cluttered seed 1", "feasibility and timed paths", "rendering")
    assert f"checking {folder}: " in term and any(f": {s}" in term for s in stages), term  # the stage then


def test_an_unreachable_level_is_refused_before_any_draw(tmp_path):
    status, out, term = _run_on_pty(["generate", "door", "--difficulty", "1/10", "--out", tmp_path], after="0")
    assert status == 2 and out == "", (status, out)
    assert "out of reach of 'door'" in term and "draw" not in term, term
