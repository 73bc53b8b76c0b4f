"""``worldgen campaign``: run a campaign recipe, or redraw a campaign's report; a thin layer over
:mod:`worldgen.campaign`.

Mistakes raise :class:`~worldgen.errors.WorldgenError`, which ``worldgen.cli.main`` prints as one line with
exit status 2; a campaign that found failures exits 1 (as a failed check does), Ctrl-C 130.
"""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import click

from worldgen.cli.context import CONTEXT as _CONTEXT
from worldgen.errors import ParameterError

__all__ = ["campaign_command"]


@click.command("campaign", context_settings=_CONTEXT)
@click.argument("args", nargs=-1, required=True, metavar="RECIPE | report DIR")
@click.option("--out", type=click.Path(path_type=Path), default=None, metavar="DIR",
              help="Campaign folder (created; an unfinished campaign of the same recipe there is resumed).")
@click.option("--jobs", type=click.IntRange(1, 256), default=1, show_default=True,
              help="Runs at once (more than 1: a local Dask cluster of that many worker processes).")
@click.option("--scheduler", default=None, metavar="ADDRESS",
              help="Run on the dask.distributed cluster at ADDRESS (e.g. tcp://host:8786); its workers share DIR.")
@click.option("--shrink/--no-shrink", default=True, show_default=True,
              help="Shrink each distinct failure for the report (runs the system again on smaller worlds).")
def campaign_command(args: tuple[str, ...], out: Optional[Path], jobs: int, scheduler: Optional[str],
                     shrink: bool) -> None:
    """Search the world space of RECIPE for where the system under test fails, into DIR.

    \b
      worldgen campaign RECIPE --out DIR [--jobs N] [--scheduler ADDRESS]
      worldgen campaign report DIR        (redraw failure map and report.md from DIR's records)

    Prints the counts and the report's path; a progress line is drawn
    on stderr when it is a terminal. Exit status 1 when any run failed. Ctrl-C keeps every
    finished run; the same command resumes. See docs/campaigns.md.
    """
    if args[0] == "report" and len(args) == 2:
        from worldgen.campaign.report import write_report

        if out is not None or jobs != 1 or scheduler is not None:
            raise ParameterError("worldgen campaign report DIR takes no --out, --jobs or --scheduler")
        click.echo(f"report: {write_report(Path(args[1]))}")
        return
    if len(args) != 1:
        raise ParameterError(f"worldgen campaign takes one RECIPE (or: report DIR), got {' '.join(args)}")
    if out is None:
        raise ParameterError("worldgen campaign RECIPE needs --out DIR, the campaign folder")
    from worldgen.campaign.recipe import load_campaign
    from worldgen.campaign.runner import CampaignInterrupted, run
    from worldgen.cli.progress import shown
    from worldgen.files import REPORT_MD_NAME

    recipe = load_campaign(args[0])
    try:
        with shown() as echo:
            summary = run(recipe, out, jobs=jobs, scheduler=scheduler, shrink=shrink)
            for line in summary.lines():
                echo(line)
    except CampaignInterrupted as exc:  # Ctrl-C: one line saying what is kept, status 130 (docs/cli.md)
        click.echo(f"error: {exc.line()}", err=True)
        raise click.exceptions.Exit(130) from None
    click.echo(f"report: {out / REPORT_MD_NAME}")
    if summary.failed:
        raise click.exceptions.Exit(1)
