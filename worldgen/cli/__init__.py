"""The ``worldgen`` command: every subcommand in this folder, each a thin wrapper over the Python API.

``main`` (:mod:`worldgen.cli.main`) is the entry point; ``world`` holds the commands about single worlds,
``pack``, ``judge`` and ``compare`` their own.
"""

from worldgen.cli.main import cli, main
from worldgen.cli.world import describe_param, parse_settings

__all__ = ["main", "cli", "parse_settings", "describe_param"]
