"""world.json: the ground truth a test asserts against (the contract: docs/world-json.md).

``build(world, files)`` turns a checked :class:`~worldgen.world.World` into a
plain dict whose field names are the public contract; ``dumps`` writes it in
the one canonical text form (sorted keys, every float through
:func:`worldgen.floats.round_float`, two-space indent, final newline), so the
same world always gives the same bytes. ``schema()`` loads the JSON Schema
shipped beside this package; ``validate()`` checks a dict against it.
"""

from __future__ import annotations

import json
from functools import lru_cache
from importlib import resources
from typing import Any, Iterable, Mapping

import numpy as np
import shapely

from worldgen.export.formats import movers_note
from worldgen.export.tasks import task_entry
from worldgen.floats import finite_or_none, round_float
from worldgen.groundtruth import difficulty, truth
from worldgen.scene.doors import door_records
from worldgen.scene.footprint import scene_footprints

__all__ = ["SCHEMA_ID", "SCHEMA_TERRAIN_ID", "build", "dumps", "schema", "validate", "free_area_ratio", "mover_entry",
           "person_entry"]

#: The value of world.json's ``schema`` field; a breaking change bumps the number.
SCHEMA_ID = "worldgen.world/1"
#: The ``schema`` of a world with terrain: a reader of /1 would take its ground for flat, so terrain
#: worlds say /2 (docs/terrain.md); flat worlds keep /1 and their bytes.
SCHEMA_TERRAIN_ID = "worldgen.world/2"

#: Segments per quarter circle when a disc footprint becomes a polygon for area sums:
#: the polygon's area is within 0.1 % of the disc's.
_DISC_QUAD_SEGS = 32


# long: world.json's top-level keys in the order the contract lists them (docs/world-json.md)
def build(world, files: Mapping[str, tuple[str, str]]) -> dict:
    """world.json of ``world`` as a plain dict (floats already rounded).

    ``files`` maps each key (``sdf``, ``mjcf``, ``urdf``, ``mesh:<path>``) to
    ``(path relative to the world folder, sha256 hex of the bytes)``.
    """
    scene, report, robot = world.scene, world.feasibility, world.robot
    (x0, y0), (x1, y1) = scene.bounds
    narrowest = finite_or_none(report.narrowest_passage)
    paths = list(report.paths) + [None] * max(0, len(world.tasks) - len(report.paths))
    meta = {
        "schema": SCHEMA_ID,
        "worldgen_version": _version(),
        "world_id": world.world_id,
        "generator": world.generator,
        "seed": int(world.seed),
        "params": dict(world.params),
        "content_hash": world.content_hash,
        "bounds": {"min": [x0, y0], "max": [x1, y1]},
        "robot": {"radius": robot.radius, "height": robot.height, "clearance": robot.clearance},
        "entities": [_entity(scene, node) for node in scene.nodes],
        "doors": door_records(scene),
        "dynamic_obstacles": [mover_entry(m, world.params, files) for m in scene.movers if not m.person],
        "tasks": [task_entry(world, task, path) for task, path in zip(world.tasks, paths)],
        "feasibility": {
            "feasible": bool(report.feasible),
            "allow_infeasible": world.allow_infeasible,
            "checker": report.checker,
            "checks": [
                {"name": c.name, "ok": bool(c.ok), "value": finite_or_none(c.value), "detail": c.detail}
                for c in report.checks
            ],
            "narrowest_passage": narrowest,
            "attempts": int(world.attempts),
            "informational": [
                {"name": c.name, "ok": bool(c.ok), "value": finite_or_none(c.value), "detail": c.detail}
                for c in getattr(report, "informational", ())
            ],
        },
        "metrics": {
            "obstacle_count": sum(1 for n in scene.nodes if n.role == "obstacle"),
            "free_area_ratio": free_area_ratio(scene, robot.height + robot.clearance),
            "narrowest_passage": narrowest,
            **truth.difficulty(world),
            "barn": truth.barn(world),
        },
        "sensors": truth.sensors(world),
        "occupancy": truth.occupancy_block(world),
        "files": {key: {"path": path, "sha256": digest} for key, (path, digest) in sorted(files.items())},
    }
    # The score reads the figures above (metrics, robot, tasks), as it would from a written world.json.
    meta["metrics"].update(difficulty.assess(meta))
    if world.preset:
        meta["preset"] = world.preset
    if getattr(world, "difficulty_request", None):
        meta["difficulty_request"] = world.difficulty_request
    if getattr(world, "edits", None):  # a curriculum's edited level: generator, params and seed, then these
        meta["edits"] = list(world.edits)
    people = [m for m in scene.movers if m.person]
    if people:  # only then, so that every world without people keeps its bytes
        meta["people"] = [person_entry(m, world.params, meta["files"]) for m in people]
    if scene.movers:  # only then, so that every static world keeps its bytes
        _add_timed(meta, world)
    if scene.terrain is not None:  # only then, so that every flat world keeps its bytes
        _add_terrain(meta, world)
    return _plain(meta)


def _add_terrain(meta: dict, world) -> None:
    """world.json's ``terrain``, the robot's climbing limits and each task's ``terrain`` (docs/terrain.md)."""
    terrain = world.scene.terrain
    meta["schema"] = SCHEMA_TERRAIN_ID
    meta["robot"].update(world.robot.limits())
    meta["terrain"] = {"elements": terrain.canonical(), "height_range": list(terrain.extent())}
    figures = list(getattr(world.feasibility, "terrain", ()))
    figures += [None] * max(0, len(meta["tasks"]) - len(figures))
    for entry, fig in zip(meta["tasks"], figures):
        entry["terrain"] = None if fig is None else fig.entry()
    meta["metrics"].update(difficulty.assess(meta))  # scored again with the terrain's inputs (docs/metrics.md)


def _add_timed(meta: dict, world) -> None:
    """The robot's limits (``robot.max_speed``, ``max_turn_rate``, ``max_acceleration``), the
    ``tracking_margin`` its timed paths keep, and each task's ``timed_path`` among the people and movers
    (docs/people.md)."""
    from worldgen.people.timed import TRACKING, limits_of

    limits = limits_of(world.params)
    meta["robot"].update(max_speed=world.params["robot_speed"], max_turn_rate=limits.turn_rate,
                         max_acceleration=limits.acceleration, tracking_margin=TRACKING)
    timed = list(getattr(world.feasibility, "timed_paths", ()))
    timed += [None] * max(0, len(meta["tasks"]) - len(timed))
    for entry, certificate in zip(meta["tasks"], timed):
        entry["timed_path"] = None if certificate is None else certificate.rows.tolist()
        entry["arrival_time"] = None if certificate is None else certificate.arrival


def dumps(meta: Mapping[str, Any]) -> str:
    """The canonical text of ``meta``: same dict, same bytes, on any machine.

    Keys sorted, two-space indent, a final newline; a list of plain numbers
    (a pose, a point, a size) stays on one line so a 1000-entity world stays
    readable. ``dumps(json.loads(dumps(m))) == dumps(m)``.
    """
    return _emit(meta, "") + "\n"


def mover_entry(mover, params: Mapping[str, Any], files: Iterable[str] = ()) -> dict:
    """The mover's ``dynamic_obstacles[]`` entry of world.json, for a world of ``params`` (which say
    whether the SDF carries movers) written with the ``files`` keys (which say whether the USD does)."""
    return {
        "name": mover.name,
        "radius": mover.radius,
        "height": mover.height,
        "trajectory": [list(row) for row in mover.trajectory],
        "loop": mover.loop,
        "formats": movers_note(params, files),
    }


def person_entry(person, params: Mapping[str, Any], files: Iterable[str] = ()) -> dict:
    """A person's ``people[]`` entry of world.json: a mover's, without ``loop`` (a person walks once
    and then stands where it stopped)."""
    from worldgen.people.behaviours import behaviours_of, reaction_entry

    entry = mover_entry(person, params, files)
    del entry["loop"]
    index = int(person.name.rsplit("_", 1)[1])
    behaviours = behaviours_of(params)
    return entry | reaction_entry(behaviours[index] if index < len(behaviours) else "impassive")


def free_area_ratio(scene, height: float) -> float:
    """Share of the bounds' area not covered by the floor shadow of any collider below ``height``.

    Shadows that touch no other shadow are summed directly (a disc inside the
    bounds exactly as pi r^2); only those that overlap, or cross the bounds, are
    unioned as polygons. A union of every shadow gives the same figure, but costs
    milliseconds per world where this costs a fraction of one.
    """
    (x0, y0), (x1, y1) = scene.bounds
    area = shapely.box(x0, y0, x1, y1)
    prints = scene_footprints(scene, height)
    if not prints:
        return 1.0
    discs = [fp for fp in prints if fp.is_disc]
    polys = np.array([fp.polygon for fp in prints if not fp.is_disc], dtype=object)
    centre = np.array([fp.centre for fp in discs], dtype=float).reshape(-1, 2)
    radius = np.array([fp.radius for fp in discs], dtype=float)
    inside_d = ((centre[:, 0] - radius >= x0) & (centre[:, 0] + radius <= x1)
                & (centre[:, 1] - radius >= y0) & (centre[:, 1] + radius <= y1))
    inside_p = np.asarray(shapely.contains_properly(area, polys), dtype=bool).reshape(-1)
    lone_d, lone_p = inside_d.copy(), inside_p.copy()
    if len(discs) > 1:
        # Candidate pairs from a tree (near-linear in the count), then the exact disc test.
        points = shapely.points(centre)
        i, j = shapely.STRtree(points).query(points, predicate="dwithin", distance=radius + radius.max())
        i, j = i[i != j], j[i != j]
        touching = np.hypot(*(centre[i] - centre[j]).T) <= radius[i] + radius[j]
        lone_d[i[touching]] = False
    if len(polys):
        tree = shapely.STRtree(polys)
        a, b = tree.query(polys, predicate="intersects")
        lone_p[a[a != b]] = False
        if discs:
            d, p = tree.query(shapely.points(centre), predicate="dwithin", distance=radius)
            lone_d[d] = False
            lone_p[p] = False
    covered = float(np.pi * np.sum(radius[lone_d] ** 2)) + float(np.sum(shapely.area(polys[lone_p])))
    rest = list(shapely.buffer(shapely.points(centre[~lone_d]), radius[~lone_d], quad_segs=_DISC_QUAD_SEGS))
    rest += list(polys[~lone_p])
    if rest:
        covered += shapely.intersection(shapely.union_all(rest), area).area
    return min(1.0, max(0.0, 1.0 - covered / area.area))


@lru_cache(maxsize=1)
def schema() -> dict:
    """The JSON Schema (draft 2020-12) of world.json, as shipped in ``worldgen/schema``."""
    text = resources.files("worldgen.schema").joinpath("world.schema.json").read_text(encoding="utf-8")
    return json.loads(text)


def validate(meta: Mapping[str, Any]) -> None:
    """Raise ``jsonschema.ValidationError`` unless ``meta`` follows the schema.

    jsonschema is one of worldgen's own dependencies (``worldgen check`` validates with it).
    """
    import jsonschema

    jsonschema.Draft202012Validator(schema()).validate(meta)


# -- pieces -----------------------------------------------------------------

def _entity(scene, node) -> dict:
    return {
        "name": node.name,
        "role": node.role,
        "static": bool(node.static),
        "pose": scene.world_pose(node.name).as_list(),
        "shape": None if node.shape is None else node.shape.describe(),
        "aabb": scene.aabb(node.name).tolist(),
    }


def _version() -> str:
    import worldgen

    return worldgen.__version__


_SCALARS = (float, int, bool, str, type(None))


def _emit(obj, indent: str) -> str:
    """Canonical text of ``obj``, rounding floats as it goes; other types go through :func:`_plain`."""
    kind = type(obj)
    if kind is not dict and kind is not list and kind not in _SCALARS:
        obj = _plain(obj)  # a tuple, a numpy value or array, a Mapping
        kind = type(obj)
    if kind is dict:
        if not obj:
            return "{}"
        if any(type(k) is not str for k in obj):
            raise TypeError(f"world.json keys must be strings, got {sorted(map(repr, obj))!r}")
        inner = indent + "  "
        items = [f"{inner}{_scalar(k)}: {_emit(obj[k], inner)}" for k in sorted(obj)]
        return "{\n" + ",\n".join(items) + "\n" + indent + "}"
    if kind is list:
        if not obj:
            return "[]"
        if all(type(v) in _SCALARS for v in obj):
            return "[" + ", ".join([_scalar(v) for v in obj]) + "]"
        inner = indent + "  "
        return "[\n" + ",\n".join([inner + _emit(v, inner) for v in obj]) + "\n" + indent + "]"
    return _scalar(obj)


def _scalar(value) -> str:
    # repr() of a rounded float is json's own float text: the shortest that reads back equal.
    kind = type(value)
    if kind is float:
        return repr(round_float(value))
    if kind is bool:
        return "true" if value else "false"
    if kind is int:
        return str(value)
    if value is None:
        return "null"
    return json.dumps(value, ensure_ascii=False)


def _plain(obj):
    """Plain JSON types, floats rounded, tuples as lists; dict keys must be strings."""
    kind = type(obj)
    if kind is float:  # the common case first: this runs once per number written
        return round_float(obj)
    if kind is str or obj is None:
        return obj
    if kind is bool or isinstance(obj, np.bool_):
        return bool(obj)
    if kind is int or isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return round_float(obj)
    if kind is list or kind is tuple:
        # Poses, points and sizes are lists of floats: round them without a call per item to _plain.
        return [round_float(v) if type(v) is float else _plain(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _plain(obj.tolist())
    if kind is dict or isinstance(obj, Mapping):
        out = {}
        for key, value in obj.items():
            if type(key) is not str:
                raise TypeError(f"world.json keys must be strings, got {key!r}")
            out[key] = _plain(value)
        return out
    if isinstance(obj, str):
        return str(obj)
    raise TypeError(f"cannot write {type(obj).__name__} {obj!r} to world.json")
