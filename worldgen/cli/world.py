"""The commands about single worlds: ``list``, ``generate``, ``preview``, ``check`` and ``presets``.

Each parses its arguments and calls the Python API; errors travel up to :func:`worldgen.cli.main.main`,
which turns them into one line and an exit status (docs/cli.md).
"""

from __future__ import annotations

import json
import os
import shutil
import textwrap
from pathlib import Path
from typing import Any, Optional, Sequence

import click

import worldgen
from worldgen.cli.context import CONTEXT as _CONTEXT
from worldgen.errors import InfeasibleError, OutputError, ParameterError, WorldgenError, did_you_mean
from worldgen.export.contract import DEFAULT_GZ_RELEASE, GZ_RELEASES
from worldgen.export.formats import ALL_FORMATS, FORMATS, SDF_VERSIONS, normalise_formats, require_formats
from worldgen.generators import all_specs, get
from worldgen.params import Param, describe_range, parse_value
from worldgen.seeding import MAX_SEED

__all__ = ["list_command", "generate_command", "preview_command", "check_command", "presets_command",
           "parse_settings", "describe_param", "parameter_tables"]


def _examples() -> str:
    try:
        lines = [ex for spec in all_specs() for ex in spec.examples]
    except WorldgenError:  # a broken plugin must not break --help; `worldgen list` reports it
        return ""
    return "\b\nExamples:\n" + "\n".join(f"  {ex}" for ex in lines) if lines else ""


@click.command("list", context_settings=_CONTEXT)
@click.argument("name", required=False, metavar="[GENERATOR]")
@click.argument("param_names", nargs=-1, metavar="[PARAMETER]...")
@click.option("--json", "as_json", is_flag=True, help="Print every generator (or GENERATOR) in full as JSON (stable key order).")
@click.option("--markdown", "as_markdown", is_flag=True,
              help="Print Markdown tables: each generator's (or GENERATOR's) own parameters, then the common ones "
                   "(the reference in docs/generators.md is this output).")
def list_command(name: Optional[str], param_names: Sequence[str], as_json: bool, as_markdown: bool) -> None:
    """The generators, one line each; with GENERATOR, its parameters: kind, default, allowed range, unit.

    \b
    worldgen list                          every generator, one line each
    worldgen list cluttered                every parameter of cluttered
    worldgen list cluttered size density   just those
    """
    specs = [get(name)] if name is not None else all_specs()
    if param_names and name is not None:
        _check_param_names(specs[0], param_names)
    if as_markdown:
        click.echo(parameter_tables(specs), nl=False)
        return
    if as_json:
        doc = {
            "worldgen_version": worldgen.__version__,
            "generators": [
                {"name": s.name, "summary": s.summary, "examples": list(s.examples),
                 "params": [describe_param(p) for p in s.all_params if not param_names or p.name in param_names]}
                for s in specs
            ],
        }
        click.echo(json.dumps(doc, indent=2, sort_keys=True))
        return
    width = max(40, min(100, shutil.get_terminal_size((100, 24)).columns))
    if name is None:
        column = max(len(s.name) for s in specs) + 2
        for spec in specs:  # one line each; 'worldgen list GENERATOR' has the whole summary
            click.echo(spec.name.ljust(column) + textwrap.shorten(spec.summary, width - column, placeholder=" ..."))
        click.echo("\n" + textwrap.fill("'worldgen list GENERATOR' shows its parameters; --markdown and --json "
                                         "print every generator in full.", width))
        return
    click.echo("\n".join(_parameter_text(specs[0], param_names, width)))


def _check_param_names(spec, names: Sequence[str]) -> None:
    known = sorted(p.name for p in spec.all_params)
    for n in names:
        if n not in known:
            raise ParameterError(f"unknown parameter '{n}' for generator '{spec.name}'{did_you_mean(n, known)}; "
                                 f"known parameters: {', '.join(known)}")


def _parameter_text(spec, names: Sequence[str], width: int) -> list[str]:
    """A generator's parameters for a terminal of ``width`` columns: its own, then those every
    generator takes; each as its name and meaning, then kind, default and allowed values."""
    from worldgen.params import COMMON_PARAMS

    common = {p.name for p in COMMON_PARAMS}
    chosen = [p for p in spec.all_params if not names or p.name in names]
    column = max(len(p.name) for p in chosen) + 4
    indent = " " * column
    from worldgen.leveling import describe_levels as levels  # the levels --difficulty can ask of it, or why none
    lines = textwrap.wrap(f"{spec.name}: {spec.summary}", width) + ([] if names else textwrap.wrap(levels(spec.name), width))
    for title, group in ((f"Parameters of {spec.name} (--set NAME=VALUE):", [p for p in chosen if p.name not in common]),
                         ("Parameters every generator takes:", [p for p in chosen if p.name in common])):
        if not group:
            continue
        lines += ["", title]
        for d in (describe_param(p) for p in sorted(group, key=lambda p: p.name)):
            unit = f" ({d['unit']})" if d["unit"] else ""
            lines += textwrap.wrap(d["doc"], width, initial_indent=f"  {d['name']}".ljust(column),
                                   subsequent_indent=indent, break_on_hyphens=False)
            lines += textwrap.wrap(f"{d['kind']}{unit}; default {d['default_text']}; {d['allowed']}", width,
                                   initial_indent=indent, subsequent_indent=indent, break_on_hyphens=False)
    if not names and spec.examples:
        lines += ["", "Examples:"]
        for ex in spec.examples:  # a long command goes on over indented lines, never cut
            lines += textwrap.wrap(ex, width, initial_indent="  ", subsequent_indent="      ", break_on_hyphens=False)
    return lines


def parameter_tables(specs) -> str:
    """Markdown: a table of each generator's own parameters, then one of the parameters every generator takes."""
    from worldgen.params import COMMON_PARAMS

    def table(params) -> list[str]:
        rows = ["| parameter | kind | default | allowed | unit | meaning |", "|---|---|---|---|---|---|"]
        for d in (describe_param(p) for p in sorted(params, key=lambda p: p.name)):
            cells = [f"`{d['name']}`", d["kind"], f"`{d['default_text']}`", d["allowed"], d["unit"] or "-", d["doc"]]
            rows.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
        return rows

    common = {p.name for p in COMMON_PARAMS}
    lines = []
    for spec in specs:
        own = [p for p in spec.params if p.name not in common]
        lines += [f"### `{spec.name}`: {spec.summary}", ""] + table(own) + [""]
    lines += ["### Every generator", ""] + table(COMMON_PARAMS) + [""]
    return "\n".join(lines)


@click.command("generate", context_settings=_CONTEXT, epilog=_examples())
@click.argument("generator", required=False)
@click.option("--preset", "preset_name", metavar="NAME",
              help="Start from preset NAME (see 'worldgen presets') or a preset .yaml file instead of a "
                   "GENERATOR; --set overrides its parameters.")
@click.option("--seed", type=click.IntRange(0, MAX_SEED), default=0, show_default=True,
              help="Seed of the first world; --count K makes seeds N .. N+K-1.")
@click.option("--set", "settings", multiple=True, metavar="KEY=VALUE",
              help="Set a generator parameter (repeatable), e.g. --set size=20,20 --set n_obstacles=50.")
@click.option("--out", type=click.Path(path_type=Path), required=True, metavar="DIR",
              help="Folder to write DIR/<world_id>/ (DIR/<preset>--<world_id>/ with --preset) into (created if missing).")
@click.option("--formats", default=",".join(FORMATS), show_default=True,
              help=f"Comma-separated formats among {', '.join(ALL_FORMATS)} (usd needs its extra, osc --ros); world.json always.")
@click.option("--sdf-version", type=click.Choice(SDF_VERSIONS), default=SDF_VERSIONS[0], show_default=True,
              help="SDFormat version: 1.9 (Gazebo Fortress to Harmonic) or 1.6 (Gazebo classic).")
@click.option("--count", type=click.IntRange(1, 100000), default=1, show_default=True,
              help="Number of worlds, one per consecutive seed.")
@click.option("--difficulty", "level", default=None, metavar="K/10",
              help="A world at difficulty level K/10, e.g. 7/10 ('worldgen list GENERATOR' names its levels).")
@click.option("--allow-infeasible", is_flag=True,
              help="For negative tests: where no draw passes, write the last checked one; "
                   "its world.json says feasible false and which checks failed.")
@click.option("--overwrite", is_flag=True,
              help="Replace a folder of the same name that holds another world (without it, that is an error).")
@click.option("--ros", is_flag=True,
              help="Also write the ROS 2 bundle in DIR/<world>/ros2/: bridge config, nav2 overrides, goals, a launch "
                   "file per world and a loop over runs (docs/ros2.md).")
@click.option("--gz-release", type=click.Choice(tuple(GZ_RELEASES)), default=None,
              help=f"With --ros: the Gazebo release whose system plugins ros2/world.sdf names "
                   f"[default: {DEFAULT_GZ_RELEASE}].")
def generate_command(generator: Optional[str], seed: int, settings: Sequence[str], out: Path, formats: str,
                     sdf_version: str, count: int, allow_infeasible: bool, overwrite: bool = False,
                     preset_name: Optional[str] = None, ros: bool = False, gz_release: Optional[str] = None,
                     level: Optional[str] = None) -> None:
    """Generate, check and write worlds of GENERATOR.

    Prints one line per world: its folder, the reference path length of each
    task and how many draws it took. Each folder appears complete or not at all.
    """
    base: dict[str, Any] = {}
    preset = None
    if preset_name is not None:
        if generator is not None:
            raise ParameterError(f"give either GENERATOR or --preset, not both (got '{generator}' and '{preset_name}')")
        from worldgen.presets import load

        preset = load(preset_name)
        generator, base = preset.generator, dict(preset.params)
    elif generator is None:
        raise ParameterError("give a GENERATOR (see 'worldgen list') or --preset NAME (see 'worldgen presets')")
    spec = get(generator)
    params = {**base, **parse_settings(spec.all_params, settings, spec.name)}
    try:
        spec.resolve(params)  # every parameter mistake surfaces before any world is drawn
    except InfeasibleError:  # a request known to be undrivable: written anyway only when asked
        if not allow_infeasible:
            raise
    require_formats(chosen := normalise_formats(formats))  # a missing extra (usd): before any world is drawn
    if "osc" in chosen and not ros:  # its scenarios start the bundle's launch file
        raise ParameterError("--formats osc writes scenarios that start the world's ROS 2 bundle: add --ros")
    if gz_release is not None and not ros:
        raise ParameterError(f"--gz-release {gz_release} names the Gazebo release of the ROS 2 bundle: add --ros")
    if seed + count - 1 > MAX_SEED:
        raise ParameterError(f"parameter 'count' must be in [1, {MAX_SEED - seed + 1}] for seed {seed}, got {count}")
    _check_out(out)
    from worldgen.cli.progress import shown

    with shown() as echo:  # a request that runs long says what it is doing, on a terminal only
        for s in range(seed, seed + count):
            world = worldgen.generate(spec.name, seed=s, allow_infeasible=allow_infeasible, difficulty=level, **params)
            world.set_provenance(preset=preset.name if preset is not None else None)  # names the folder <preset>--<world_id>
            folder = world.write(out, formats=chosen, sdf_version=sdf_version, overwrite=overwrite,
                                 ros=(gz_release or DEFAULT_GZ_RELEASE) if ros else False)
            echo(f"{folder}\tpath {_lengths(world)} m\t{_draws(world)}{_verdict(world)}")


def _lengths(world) -> str:
    return ",".join("-" if p is None else f"{p.length:.3f}" for p in world.feasibility.paths)


def _draws(world) -> str:
    """"attempts N": the generator's attempts for the world's own seed (1: its first draw passed); a level request
    first says the level, its seed and "draws K", the worlds drawn to reach the level (each with its own attempts)."""
    request = world.difficulty_request  # a level request: the level, its seed and every draw it took
    levels = f"level {request['level']}, request seed {request['seed']}\tdraws {len(request['draws'])}\t" if request else ""
    return f"{levels}attempts {world.attempts}"


def _verdict(world) -> str:
    failed = ",".join(c.name for c in world.feasibility.failed())
    return f"\tinfeasible: {failed}" if failed else ""


@click.command("preview", context_settings=_CONTEXT)
@click.argument("world_dirs", nargs=-1, required=True, metavar="WORLD_DIR...",
                type=click.Path(exists=True, file_okay=False, path_type=Path))
@click.option("--width", type=int, default=800, show_default=True, help="Image width in px (400 to 4000).")
def preview_command(world_dirs: Sequence[Path], width: int) -> None:
    """Redraw preview.png of each world folder from its world.json.

    The picture is not listed in world.json's files, so world.json is left as it is.
    """
    from worldgen.export.preview import write_preview

    for folder in world_dirs:
        click.echo(str(write_preview(folder, width)))


@click.command("check", context_settings=_CONTEXT)
@click.argument("world_dirs", nargs=-1, required=True, metavar="WORLD_DIR...",
                type=click.Path(exists=True, file_okay=False, path_type=Path))
def check_command(world_dirs: Sequence[Path]) -> None:
    """Re-verify received world folders: hashes, schema, regeneration, feasibility.

    Prints "OK DIR" or "FAIL DIR: CHECK: DETAIL" per folder; exit status 1 if any failed.
    """
    from worldgen.cli.progress import shown
    from worldgen.groundtruth.folder import is_world_folder
    from worldgen.verify import check_folder

    for folder in world_dirs:  # a usage mistake, before any check: a folder of worlds is not a world folder
        inner = [p for p in folder.iterdir() if is_world_folder(p)]
        if inner and not is_world_folder(folder):
            raise ParameterError(f"'{folder}' is a folder of {len(inner)} world folders, not a world folder "
                                 f"(no world.json); give them: worldgen check {folder}/*")
    failed = 0
    with shown() as echo:
        for folder in world_dirs:
            outcome = check_folder(folder)
            failed += not outcome.ok
            echo(outcome.line())
    if failed:
        raise click.exceptions.Exit(1)


@click.command("presets", context_settings=_CONTEXT)
@click.option("--json", "as_json", is_flag=True, help="Print every preset in full as JSON (stable key order).")
def presets_command(as_json: bool) -> None:
    """List the shipped presets: name and description (use with 'generate --preset NAME')."""
    from worldgen.presets import all_presets

    found = all_presets()
    if as_json:
        click.echo(json.dumps([{"name": p.name, "description": p.description, "reproduces": p.reproduces,
                                "generator": p.generator, "params": dict(p.params)} for p in found],
                              indent=2, sort_keys=True))
        return
    width = max((len(p.name) for p in found), default=0)
    for p in found:
        click.echo(f"{p.name.ljust(width)}  {p.description}")


def parse_settings(params: Sequence[Param], settings: Sequence[str], generator: str) -> dict[str, Any]:
    """``["key=value", ...]`` -> ``{key: value}``, each value parsed for its parameter's kind.

    Values are only parsed here; :meth:`GeneratorSpec.resolve` checks them. A
    key given twice keeps its last value, as on most command lines.
    """
    by_name = {p.name: p for p in params}
    out: dict[str, Any] = {}
    for item in settings:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise ParameterError(f"--set expects KEY=VALUE (e.g. --set n_obstacles=50), got {item!r}")
        if key not in by_name:
            hint = " (the seed is set with --seed)" if key == "seed" else ""
            raise ParameterError(
                f"unknown parameter '{key}' for generator '{generator}'{hint or did_you_mean(key, by_name)}; "
                f"known parameters: {', '.join(sorted(by_name))}"
            )
        out[key] = parse_value(by_name[key], text)
    return out


def describe_param(p: Param) -> dict[str, Any]:
    """One parameter as ``worldgen list`` shows it (also its --json form)."""
    if p.kind == "range":
        allowed = f"min <= max, each {describe_range(p)}"
    elif p.kind in ("pair", "triple"):
        allowed = f"each {describe_range(p)}"
    elif p.kind == "list":
        allowed = f"comma-separated numbers, each {describe_range(p)}"
    elif p.kind == "words":
        allowed = f"comma-separated, each {describe_range(p)}"
    elif p.kind == "int":
        allowed = f"integer {describe_range(p)}"
    else:
        allowed = describe_range(p)
    if p.optional:
        allowed += " or none"
    return {
        "name": p.name, "kind": p.kind, "default": p.default, "default_text": _value_text(p.default),
        "allowed": allowed, "low": p.low, "high": p.high, "choices": list(p.choices),
        "optional": p.optional, "unit": p.unit, "doc": p.doc,
    }


def _value_text(value: Any) -> str:
    """A value as it would be typed after --set key=."""
    if value is None:
        return "none"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (list, tuple)):
        return ",".join(_value_text(v) for v in value)
    return f"{value:g}" if isinstance(value, float) else str(value)


def _check_out(out: Path) -> None:
    """Fail before drawing anything when --out can never be written.

    The nearest existing folder on the way to ``out`` must be a writable
    folder; ``World.write`` creates what is missing below it.
    """
    if out.exists() and not out.is_dir():
        raise OutputError(f"--out '{out}' is not a folder; give a folder to write worlds into")
    base = out
    while not base.exists() and base.parent != base:
        base = base.parent
    if not base.is_dir():
        raise OutputError(f"--out '{out}' cannot be created: '{base}' is a file, not a folder")
    if not os.access(base, os.W_OK | os.X_OK):
        raise OutputError(f"--out '{out}' is not writable (no write permission on '{base}')")

