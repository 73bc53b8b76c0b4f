"""scenario.yaml: the world's tasks as a scenario spec, beside world.json in every world folder.

The shape follows the common scenario-spec layout that simulation test
runners read (a name, a description, the world file, the robot's spawn pose,
success criteria and failure conditions), so a runner that knows nothing of
world.json can still launch and judge a task:

    name: cluttered-s7-1f3a9c0b
    description: ...
    world: world.sdf                  # the first written of world.sdf, world.mjcf.xml, world.urdf
    robot: {radius: 0.2, height: 0.4, spawn: {x: .., y: .., z: 0.0, yaw: ..}}
    tasks:
      - id: task_0
        spawn: {x, y, z, yaw}
        success_criteria:
          - {type: robot_reaches_waypoint, waypoint: [x, y], tolerance: 0.2}
          - {type: max_time, seconds: 30.79}
          - {type: door_opened, door: door_0}         # each leaf that stands in the path as it starts
        failure_conditions:
          - {type: collision}
          - {type: timeout, seconds: 30.79}

The top-level ``robot.spawn``, ``success_criteria`` and ``failure_conditions``
repeat the first task's, for runners that know one task per scenario.

It is built from the World (scene, tasks, proven paths), not from world.json,
so that world.json can list it with its SHA-256 like every other file. The
bytes are canonical: ``yaml.safe_dump`` with sorted keys of values already
rounded by :mod:`worldgen.floats`.
"""

from __future__ import annotations

from typing import Any, Iterable, Optional

from worldgen.export.formats import FILE_NAMES, FORMATS, normalise_formats
from worldgen.export.tasks import leaves_on_path, task_entry
from worldgen.files import SCENARIO_NAME

__all__ = ["scenario", "dumps", "files", "read"]



def scenario(world, formats: Iterable[str] = FORMATS) -> dict[str, Any]:
    """The scenario spec of ``world`` as a plain dict; ``world`` names the first written of SDF, MJCF, URDF."""
    from worldgen.floats import round_float

    paths = list(world.feasibility.paths) + [None] * len(world.tasks)
    tasks = []
    for task, path in zip(world.tasks, paths):
        leaves = leaves_on_path(world, path)
        seconds = task_entry(world, task, path, leaves)["time_limit"]
        limit: Optional[float] = None if seconds is None else round_float(seconds)
        success = [{"type": "robot_reaches_waypoint", "waypoint": [round_float(task.goal.x), round_float(task.goal.y)],
                    "tolerance": round_float(task.goal_tolerance)}]
        failure: list[dict[str, Any]] = [{"type": "collision"}]
        if limit is not None:
            success.append({"type": "max_time", "seconds": limit})
            failure.append({"type": "timeout", "seconds": limit})
        success += [{"type": "door_opened", "door": name} for name in leaves]
        tasks.append({
            "id": task.id,
            "spawn": {"x": round_float(task.spawn.x), "y": round_float(task.spawn.y), "z": round_float(task.spawn.z),
                      "yaw": round_float(task.spawn.yaw)},
            "success_criteria": success,
            "failure_conditions": failure,
        })
    first = tasks[0] if tasks else {"spawn": None, "success_criteria": [], "failure_conditions": []}
    return {
        "name": world.world_id,
        "description": f"worldgen '{world.generator}' world, seed {world.seed}: drive the footprint from spawn to goal "
                       f"without touching any collider",
        "world": FILE_NAMES[normalise_formats(formats)[0]],
        "robot": {"radius": world.robot.radius, "height": world.robot.height, "spawn": first["spawn"]},
        "success_criteria": first["success_criteria"],
        "failure_conditions": first["failure_conditions"],
        "tasks": tasks,
    }


def dumps(spec: dict) -> str:
    import yaml

    return yaml.dump(spec, Dumper=_plain_dumper(), sort_keys=True, default_flow_style=None, width=100,
                     allow_unicode=False)


_DUMPER = None


def _plain_dumper():
    """libyaml's emitter where PyYAML has it (0.2 ms a world against 1 to 3 ms for the pure-Python one;
    the same bytes), with aliases off: the top level repeats the first task's blocks, written out twice."""
    global _DUMPER
    if _DUMPER is None:
        import yaml

        base = getattr(yaml, "CSafeDumper", yaml.SafeDumper)
        _DUMPER = type("_PlainDumper", (base,), {"ignore_aliases": lambda self, data: True})
    return _DUMPER


def files(world, formats: Iterable[str] = FORMATS) -> dict[str, tuple[str, bytes]]:
    """``{"scenario": ("scenario.yaml", bytes)}`` for :meth:`World.rendered_files`."""
    return {"scenario": (SCENARIO_NAME, dumps(scenario(world, formats)).encode())}


def read(folder) -> dict:
    """The scenario spec of a written world folder (``yaml.safe_load``)."""
    from pathlib import Path

    import yaml

    from worldgen.errors import ParameterError

    path = Path(folder)
    path = path / SCENARIO_NAME if path.is_dir() else path
    try:
        data = yaml.safe_load(path.read_text())
    except (OSError, yaml.YAMLError) as exc:
        raise ParameterError(f"cannot read scenario file '{path}': {exc}") from None
    if not isinstance(data, dict):
        raise ParameterError(f"scenario file '{path}' must hold a mapping, got {type(data).__name__}")
    return data
