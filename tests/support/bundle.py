"""What the ROS 2 bundle's tests share: a two-task world with its bundle, and loading a bundle script."""

import importlib.util
from pathlib import Path

import worldgen

__all__ = ["bundle_world", "load_script"]


def bundle_world():
    """The world the bundle tests write (two tasks, so per-task files differ)."""
    return worldgen.generate("cluttered", seed=7, size=[6, 6], n_obstacles=6, n_tasks=2)


def load_script(path: Path, name: str):
    """A bundle script as a module (they import only the standard library and PyYAML at the top)."""
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
