"""urdfdom's ``check_urdf`` as a reference tool (skips on a laptop without it, fails on CI)."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

from support import missing_tool

__all__ = ["check_urdf"]


def check_urdf(path) -> str:
    """Run ``check_urdf path``; fail the test with its output unless it parses the file. Returns stdout."""
    exe = shutil.which("check_urdf")
    if exe is None:
        missing_tool("urdfdom's check_urdf (apt install liburdfdom-tools)")
    proc = subprocess.run([exe, str(Path(path))], capture_output=True, text=True, timeout=60)
    out = proc.stdout + proc.stderr
    assert proc.returncode == 0 and "Successfully Parsed XML" in proc.stdout, f"check_urdf rejected {path}:\n{out}"
    return proc.stdout
