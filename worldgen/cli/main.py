"""The ``worldgen`` command: a thin click layer over the Python API.

It parses, calls :func:`worldgen.generate` and :meth:`World.write`, and turns
every :class:`~worldgen.errors.WorldgenError` (and every click usage error)
into one line on stderr, ``error: ...``, with exit status 2 for a usage mistake
and 3 when no such world exists (docs/cli.md): a user's mistake never shows a
traceback. Anything else that escapes is a bug and keeps its
traceback on purpose.
"""

from __future__ import annotations

import errno
import sys
from typing import Optional, Sequence

import click

import worldgen
from worldgen.cli.campaign import campaign_command
from worldgen.cli.compare import compare_command
from worldgen.cli.context import CONTEXT
from worldgen.cli.drive import drive_command
from worldgen.cli.judge import judge_command
from worldgen.cli.pack import pack_group
from worldgen.cli.world import check_command, generate_command, list_command, presets_command, preview_command
from worldgen.errors import EXIT_USAGE, WorldgenError

__all__ = ["main", "cli"]


@click.group(context_settings=CONTEXT,
             epilog="Run 'worldgen list' for the generators, 'worldgen list GENERATOR' for its parameters.")
@click.version_option(worldgen.__version__, "--version", prog_name="worldgen", message="%(prog)s %(version)s")
def cli() -> None:
    """Seeded, feasibility-checked test worlds for robot simulation.

    Each world is written as SDF, MJCF and URDF plus world.json, the ground
    truth (spawn, goal, shortest path, clearances) a test asserts against.
    """


for _command in (list_command, generate_command, preview_command, check_command, presets_command, pack_group,
                 compare_command, judge_command, drive_command, campaign_command):
    cli.add_command(_command)


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Run the command line; return the exit status (0 ok, 1 a check failed, 2 a usage mistake, 3 no such world)."""
    try:
        rv = cli.main(args=list(argv) if argv is not None else None, prog_name="worldgen", standalone_mode=False)
        return rv if isinstance(rv, int) else 0
    except click.exceptions.NoArgsIsHelpError as exc:  # bare `worldgen`: help is the answer
        click.echo(exc.ctx.get_help() if exc.ctx else str(exc))
        return 0
    except click.ClickException as exc:
        ctx = getattr(exc, "ctx", None)  # usage errors carry the command they are about; other errors do not
        hint = f" (see '{ctx.command_path} --help')" if ctx is not None else ""
        click.echo(f"error: {_one_line(exc.format_message())}{hint}", err=True)
        return EXIT_USAGE
    except WorldgenError as exc:
        click.echo(f"error: {_one_line(str(exc))}", err=True)
        return exc.exit_status
    except click.Abort:
        click.echo("error: aborted", err=True)
        return 130
    except OSError as exc:
        if exc.errno == errno.EPIPE:  # `worldgen list | head`: the reader left, nothing is wrong
            return 0
        raise


if __name__ == "__main__":
    sys.exit(main())
