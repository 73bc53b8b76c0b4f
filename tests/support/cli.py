"""Running the ``worldgen`` command in a real process."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

__all__ = ["WORLDGEN", "QUICK", "run", "world_dirs"]

_SCRIPT = Path(sys.executable).with_name("worldgen")
WORLDGEN = [str(_SCRIPT)] if _SCRIPT.exists() else [sys.executable, "-m", "worldgen"]
#: A small, quick world for the end-to-end runs.
QUICK = ["--set", "size=6,6", "--set", "n_obstacles=6"]


def run(*args, cwd=None, cmd=None) -> subprocess.CompletedProcess:
    return subprocess.run((cmd or WORLDGEN) + [str(a) for a in args], capture_output=True, text=True,
                          cwd=cwd, timeout=120)


def world_dirs(out: Path) -> list[Path]:
    return sorted(p for p in out.iterdir() if p.is_dir()) if out.exists() else []
