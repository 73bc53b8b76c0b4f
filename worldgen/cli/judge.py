"""``worldgen judge``: a thin click layer over :mod:`worldgen.judge.runs` and :mod:`worldgen.judge.report`.

Mistakes raise :class:`~worldgen.errors.WorldgenError`, which ``worldgen.cli.main`` prints as one
line with exit status 2; criteria that do not hold (or a bag that could not be judged) exit 1.
Every bag not judged, and every failed run, is named on stderr with its reason.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Optional, Sequence

import click

from worldgen.cli.context import CONTEXT as _CONTEXT
from worldgen.export.contract import CMD_VEL, GROUND_TRUTH, ODOM

__all__ = ["judge_command", "bag_lines", "BAG_LINES"]

#: Refused or failed bags named one per line on stderr; the rest are counted (report.md lists them all).
BAG_LINES = 20


def bag_lines(rows: Sequence[dict], limit: int = BAG_LINES) -> list[str]:
    """One line per bag that was not judged or whose run failed: its name, its outcome and the reason."""
    bad = [r for r in rows if r.get("outcome") != "success"]
    out = []
    for r in bad[:limit]:
        reason = " ".join(str(r.get("reason") or "").split())
        prefix = f"bag '{r['bag']}': "
        reason = reason[len(prefix):] if reason.startswith(prefix) else reason
        if r.get("outcome") == "unjudged":
            out.append(f"unjudged {r['bag']}: {reason}")
        else:
            out.append(f"failed {r['run']} ({r['bag']}): {reason}")
    if len(bad) > limit:
        out.append(f"... and {len(bad) - limit} more not judged or failed (every one in report.md)")
    return out



@click.command("judge", context_settings=_CONTEXT, epilog="""\b
Examples:
  worldgen judge runs/*.mcap --world worlds/cluttered-s0-1f3a9c0b --criteria criteria.yaml --out report
  worldgen judge --runs runs.csv --pack packs/nav-v1 --criteria criteria.yaml --out report
  worldgen judge runs/run-* --pack packs/nav-v1 --out report      (worlds named in the bags' metadata)
""")
@click.argument("bags", nargs=-1, type=click.Path(path_type=Path), metavar="[BAG]...")
@click.option("--world", type=click.Path(path_type=Path), metavar="DIR", help="The world folder every BAG ran in.")
@click.option("--pack", type=click.Path(path_type=Path), metavar="DIR",
              help="A built pack, or a folder of world folders: worlds by the id a --runs row or a bag's "
                   "metadata (worldgen.world_id) names.")
@click.option("--runs", "runs_table", type=click.Path(path_type=Path), metavar="TABLE",
              help="CSV with columns bag, world (id in --pack, or a world folder), optional task, run.")
@click.option("--criteria", type=click.Path(path_type=Path), metavar="FILE",
              help="Acceptance criteria (YAML, docs/testing.md); without it, every run must meet its scenario.")
@click.option("--out", type=click.Path(path_type=Path), required=True, metavar="DIR",
              help="The report folder (created; an earlier report there is replaced).")
@click.option("--start", type=click.Choice(["command", "goal", "motion", "bag"]), default="command", show_default=True,
              help="Where a run starts: first non-zero /cmd_vel, goal sent, first 0.1 m of motion (BARN), bag start.")
@click.option("--pose-topic", default=GROUND_TRUTH.name, show_default=True, help="The simulator's ground-truth pose topic.")
@click.option("--odom-topic", default=ODOM.name, show_default=True)
@click.option("--cmd-topic", default=CMD_VEL.name, show_default=True)
@click.option("--base-frame", "base_frames", multiple=True, metavar="FRAME",
              help="Robot base frame(s) in /tf, in order of preference [default: base_footprint, base_link].")
@click.option("--spawn-tolerance", type=click.FloatRange(0, None), default=0.25, show_default=True,
              help="m a run may start from its task's spawn before the bag is refused as being in the wrong world.")
@click.option("--progress/--no-progress", default=None,
              help="Progress on stderr: a bar on a terminal, a line per tenth of the batch elsewhere "
                   "[default: on a terminal only].")
def judge_command(bags: Sequence[Path], world: Optional[Path], pack: Optional[Path], runs_table: Optional[Path],
                  criteria: Optional[Path], out: Path, start: str, pose_topic: str, odom_topic: str, cmd_topic: str,
                  base_frames: Sequence[str], spawn_tolerance: float, progress: Optional[bool]) -> None:
    """Judge recorded ROS bags (rosbag2 folders, .mcap, .db3) against acceptance criteria.

    Each bag is read into a trajectory (ground-truth pose topic, else the TF chain
    map->odom->base, else /odom from the spawn), judged against its world's ground truth
    and scenario, and written with the verdict to OUT: report.json, report.csv,
    report.md and runs/RUN.png. Exit status 0 when every criterion holds and every bag
    was read, 1 otherwise, 2 on bad input. Needs the ros extra: pip install 'worldgen[ros]'.
    """
    from worldgen.judge.report import write_report
    from worldgen.judge.runs import judge
    from worldgen.ros.deps import require_rosbags

    require_rosbags()
    options = {"pose_topic": pose_topic, "odom_topic": odom_topic, "cmd_topic": cmd_topic,
               "spawn_tolerance": spawn_tolerance}
    if base_frames:
        options["base_frames"] = tuple(base_frames)
    tty = sys.stderr.isatty()
    if tty if progress is None else progress:
        from worldgen.judge.runs import plan

        total = len(plan(bags, world=world, pack=pack, runs=runs_table))
        if tty:
            with click.progressbar(length=total, label="judging", file=sys.stderr) as bar:
                done = [0]

                def tick(k: int) -> None:
                    bar.update(k - done[0])
                    done[0] = k

                result = judge(bags, criteria, world=world, pack=pack, runs=runs_table, start=start,
                               read_options=options, progress=tick)
        else:  # a log (CI): a line at every tenth of the batch instead of a redrawn bar
            def line(k: int) -> None:
                if k == total or k * 10 // total != (k - 1) * 10 // total:
                    click.echo(f"judging: {k} of {total} bags ({100 * k // total}%)", err=True)

            result = judge(bags, criteria, world=world, pack=pack, runs=runs_table, start=start, read_options=options,
                           progress=line)
    else:
        result = judge(bags, criteria, world=world, pack=pack, runs=runs_table, start=start, read_options=options)
    folder = write_report(result, out)
    for text in bag_lines(result.report["runs"]):
        click.echo(text, err=True)
    s = result.report["summary"]
    click.echo(f"{s['bags']} bags, {s.get('runs', 0)} judged, {s.get('successes', 0)} succeeded, "
               f"{s['unjudged']} unjudged: {'PASS' if result.passed else 'FAIL'}")
    for line in result.report["failures"]:
        click.echo(f"FAILED {line}")
    click.echo(f"report: {folder}")
    if not result.passed:
        raise click.exceptions.Exit(1)
