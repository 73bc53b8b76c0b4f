"""``worldgen pack ...``: the command group, a thin layer over :mod:`worldgen.pack`.

Mistakes raise :class:`~worldgen.errors.WorldgenError`, which ``worldgen.cli.main``
prints as one line with exit status 2; a failed verification exits 1.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Optional

import click

from worldgen.cli.context import CONTEXT as _CONTEXT

__all__ = ["pack_group"]



@click.group("pack", context_settings=_CONTEXT)
def pack_group() -> None:
    """Build, verify, list and archive world packs (many worlds from one recipe)."""


@pack_group.command("build", context_settings=_CONTEXT)
@click.argument("recipe", type=click.Path(path_type=Path))
@click.option("--out", type=click.Path(path_type=Path), required=True, metavar="PACK",
              help="Pack folder (created; an unfinished build there is resumed).")
@click.option("--jobs", type=click.IntRange(1, 256), default=1, show_default=True, help="Worker processes.")
@click.option("--executor", type=click.Choice(["local", "dask"]), default="local", show_default=True,
              help="local: a process pool of --jobs; dask: a dask.distributed cluster (optional extra).")
@click.option("--scheduler", default=None, metavar="ADDRESS", help="The dask scheduler, e.g. tcp://host:8786.")
def build_command(recipe: Path, out: Path, jobs: int, executor: str, scheduler: Optional[str]) -> None:
    """Build every world of RECIPE into PACK; rerun the same command to finish a killed build.

    A progress line (count, rate, ETA) is drawn on stderr when it is a terminal. Ctrl-C stops
    within about a second, keeping every finished world; the rerun builds the rest.
    """
    from worldgen.pack.build import BuildInterrupted, build_pack
    from worldgen.pack.recipe import load_recipe

    parsed = load_recipe(recipe)
    stream = sys.stderr if sys.stderr.isatty() else None
    try:
        summary = build_pack(parsed, out, jobs=jobs, progress=stream, executor=executor, scheduler=scheduler)
    except BuildInterrupted as exc:  # Ctrl-C: one line saying what is kept, status 130 (docs/cli.md)
        click.echo(f"error: {exc.line()}", err=True)
        raise click.exceptions.Exit(130) from None
    for line in summary.lines():
        click.echo(line)
    click.echo(f"pack: {out}")


@pack_group.command("verify", context_settings=_CONTEXT)
@click.argument("pack", type=click.Path(exists=True, path_type=Path))
@click.option("--regenerate", is_flag=True, help="Also rebuild every world and compare it byte for byte.")
def verify_command(pack: Path, regenerate: bool) -> None:
    """Check every file's sha256, each world.json's schema and index.csv (PACK: folder or archive).

    Prints OK/FAIL per world; exit status 1 if anything failed.
    """
    from worldgen.pack.verify import verify_pack

    failed = 0
    for ok, line in verify_pack(pack, regenerate=regenerate):
        failed += not ok
        click.echo(line)
    if failed:
        click.echo(f"{failed} failed", err=True)
        raise click.exceptions.Exit(1)


@pack_group.command("info", context_settings=_CONTEXT)
@click.argument("pack", type=click.Path(exists=True, path_type=Path))
def info_command(pack: Path) -> None:
    """Name, version, formats, world count, generators and metric ranges of PACK."""
    from worldgen.pack.manifest import METRICS
    from worldgen.pack.pack import Pack

    p = Pack.open(pack)
    m = p.manifest
    click.echo(f"name: {m['name']}")
    click.echo(f"worldgen_version: {m['worldgen_version']}")
    click.echo(f"formats: {', '.join(m['formats'])} (sdf {m['sdf_version']}), preview: {str(m['preview']).lower()}")
    click.echo(f"worlds: {len(p)}, rejected jobs: {len(m['rejected'])}")
    gens: dict[str, int] = {}
    for w in p:
        gens[w.generator] = gens.get(w.generator, 0) + 1
    click.echo("generators: " + ", ".join(f"{g} {n}" for g, n in sorted(gens.items())))
    levels: dict[str, int] = {}
    for w in p:  # the level each world landed in (metrics.difficulty_level); "none" without a path
        level = w.metrics.get("difficulty_level")
        key = str(level) if level is not None else "none"
        levels[key] = levels.get(key, 0) + 1
    if levels:
        order = sorted(levels, key=lambda k: (k == "none", int(k) if k != "none" else 0))
        click.echo("difficulty levels: " + ", ".join(f"{k}: {levels[k]}" for k in order))
    asked = [w.get("level") for w in m["worlds"] if w.get("level") is not None]
    if asked:
        click.echo(f"asked for by level: {len(asked)} worlds at levels {', '.join(str(k) for k in sorted(set(asked)))}")
    for k in METRICS:
        vals = [w.metrics[k] for w in p if w.metrics.get(k) is not None]
        if vals:
            click.echo(f"  {k}: min {min(vals):g}, max {max(vals):g}")
    p.close()


@pack_group.command("ls", context_settings=_CONTEXT)
@click.argument("pack", type=click.Path(exists=True, path_type=Path))
@click.option("--where", "where", default=None, metavar="EXPR",
              help="e.g. \"narrowest_passage < 1.0 and obstacle_count >= 5\" (METRIC OP NUMBER, joined by 'and').")
def ls_command(pack: Path, where: Optional[str]) -> None:
    """One line per world: index, world_id and key metrics (tab-separated)."""
    from worldgen.pack.pack import Pack

    p = Pack.open(pack)
    chosen = p.filter(where) if where is not None else p
    for w in chosen:
        m = w.metrics
        click.echo(f"{w.index}\t{w.world_id}\tnarrowest_passage={m.get('narrowest_passage')}"
                   f"\tobstacle_count={m.get('obstacle_count')}\tpath_length={m.get('path_length')}"
                   f"\tdifficulty_level={m.get('difficulty_level')}")
    p.close()


@pack_group.command("archive", context_settings=_CONTEXT)
@click.argument("pack", type=click.Path(exists=True, file_okay=False, path_type=Path))
@click.option("--out", type=click.Path(path_type=Path), default=None, metavar="FILE",
              help="Archive path (default: PACK.tar.gz beside PACK).")
def archive_command(pack: Path, out: Optional[Path]) -> None:
    """Write PACK to one deterministic .tar.gz that 'pack verify' and Pack.open read."""
    from worldgen.pack.archive import write_archive

    click.echo(str(write_archive(pack, out)))
