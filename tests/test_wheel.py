"""A built wheel, installed into a fresh venv, is a working worldgen.

`make test` installs editable, which finds every module from the source tree
whether or not the packaging lists it; only a real wheel shows what a user of
`pip install worldgen` gets.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
import venv
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def source_modules() -> set[str]:
    names = set()
    for folder, _, files in os.walk(REPO / "worldgen", followlinks=True):  # templates is a symlink
        for file in files:
            if file.endswith(".py"):
                parts = (Path(folder) / file).relative_to(REPO).with_suffix("").parts
                names.add(".".join(parts[:-1] if parts[-1] == "__init__" else parts))
    return names


@pytest.fixture(scope="module")
def wheel_venv(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("wheel")
    src = tmp / "src"
    src.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(REPO / name, src / name)
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc")
    shutil.copytree(REPO / "templates", src / "templates", ignore=ignore)
    shutil.copytree(REPO / "worldgen", src / "worldgen", ignore=ignore, symlinks=True)
    build = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--quiet", "--no-deps", "-w", str(tmp / "dist"), str(src)],
        capture_output=True, text=True,
    )
    assert build.returncode == 0, build.stderr[-2000:]
    (wheel,) = (tmp / "dist").glob("worldgen-*.whl")

    env_dir = tmp / "venv"
    venv.EnvBuilder(with_pip=False).create(env_dir)
    py = env_dir / "bin" / "python"
    site = Path(subprocess.check_output(
        [str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], text=True).strip())
    # The wheel goes in with this interpreter's pip; its dependencies come from the test venv's
    # site-packages, added as a plain path (its .pth files, the editable worldgen among them,
    # are not processed), so the only worldgen the fresh venv sees is the wheel's.
    install = subprocess.run(
        [sys.executable, "-m", "pip", "--python", str(py), "install", "--quiet", "--no-deps",
         "--no-compile", str(wheel)], capture_output=True, text=True,
    )
    assert install.returncode == 0, install.stderr[-2000:]
    (site / "test-deps.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    return env_dir


def run(env_dir: Path, *args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([str(a) for a in args], cwd=cwd, capture_output=True, text=True, timeout=300)


def test_every_module_ships_and_imports(wheel_venv, tmp_path):
    code = (
        "import importlib, pkgutil, worldgen;"
        "print(worldgen.__file__);"
        "names = ['worldgen'] + [m.name for m in pkgutil.walk_packages(worldgen.__path__, 'worldgen.')];"
        "[importlib.import_module(n) for n in names];"
        "print('\\n'.join(sorted(names)))"
    )
    out = run(wheel_venv, wheel_venv / "bin" / "python", "-c", code, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    first, *names = out.stdout.split()
    assert first.startswith(str(wheel_venv)), f"imported worldgen from {first}, not the wheel"
    assert set(names) == source_modules()
    assert (Path(first).parent / "py.typed").is_file(), "the wheel must carry py.typed (PEP 561)"
    # worldgen drive --sim gazebo compiles this source on first use
    assert (Path(first).parent / "sim" / "drive_bridge.cc").is_file(), "the wheel must carry the Gazebo bridge source"


@pytest.mark.parametrize("args", [
    ["generate", "cluttered", "--seed", "0"],
    ["generate", "door", "--seed", "0"],
    ["generate", "--preset", "lidar_wall"],
    ["generate", "minimal", "--seed", "0", "--ros"],
])
def test_installed_cli_generates(wheel_venv, tmp_path, args):
    out = run(wheel_venv, wheel_venv / "bin" / "worldgen", *args, "--out", tmp_path / "w", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    (world_json,) = (tmp_path / "w").glob("*/world.json")
    for name in ("world.sdf", "world.mjcf.xml", "world.urdf", "map.pgm", "preview.png"):
        assert (world_json.parent / name).stat().st_size > 0
    if "--ros" in args:  # the bundle's scripts ship as templates (templates/ros2/*.py.in)
        for name in ("ros2/send_goal.py", "ros2/run_loop.py", "ros2/bridge.yaml"):
            assert (world_json.parent / name).stat().st_size > 0
