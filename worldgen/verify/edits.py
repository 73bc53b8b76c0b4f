"""Small edits of a proven world, each re-proved: the level edits of an adaptive curriculum (ACCEL's idea).

An edit changes one thing of a world's scene or tasks:

``move``       an obstacle slides by up to :data:`STEP` m (its yaw kept);
``resize``     an obstacle's floor footprint scales by a factor in :data:`SCALE` (box sides, cylinder radius);
``add``        a new box or cylinder, sized from the generator's own ranges where it has them
               (``box_size``, ``cylinder_radius``, ``obstacle_height``), anywhere on the floor;
``remove``     an obstacle goes;
``move_goal``  a task's goal slides by up to :data:`STEP` m (its tolerance and yaw kept; never nearer the
               spawn than the generator's ``min_spawn_goal_distance``).

Three more operators are never drawn, only recorded by :func:`worldgen.shrink`: ``remove`` of any root
obstacle without children (a mesh too), ``remove_mover`` of a scripted mover and ``remove_person`` of a
person. In a world with people every edit is followed by the people's walk made again and certified anew
(:mod:`worldgen.verify.rewalk`): a world whose people cannot be certified after it is not kept.

Only the root nodes whose role is ``obstacle`` and whose shape is a box or a cylinder are edited (walls,
doors, frames and floors never); an edited obstacle stays inside the scene's bounds. Worlds with movers
or people are not edited (their timed proofs follow the obstacles): :func:`edit_world` returns None.

Every edited scene goes through :func:`worldgen.feasibility.check`, the same exact checker a generated
world passes, and is kept only when feasible: an :class:`EditedWorld` always carries a certificate and a
reference path per task (among people, a timed path per task too). An edit is recorded as plain data (its
operator, target and new values), so :func:`replay_edits` rebuilds the same world from (generator, params,
seed, edits), re-proving it. Randomness comes from :func:`worldgen.seeding.edit_rng` of a seed the caller draws.
"""

from __future__ import annotations

import hashlib
import json
import math
from functools import cached_property
from typing import Any, Optional, Sequence

import numpy as np

from worldgen import feasibility
from worldgen.errors import ParameterError
from worldgen.floats import round_float
from worldgen.scene import Box, Cylinder, Material, Node, Pose, Scene, Task
from worldgen.seeding import edit_rng
from worldgen.verify.rewalk import people_plan, settle
from worldgen.world import World

__all__ = ["EDITS", "STEP", "SCALE", "TRIES", "EditedWorld", "edit_world", "apply_edit", "replay_edits", "removable",
           "with_edits", "editable"]

#: The edit operators, in the order their names are drawn from.
EDITS = ("move", "resize", "add", "remove", "move_goal")
#: What shrinking records: removing an obstacle (any root obstacle without children) or a scripted mover.
#: Largest slide of an obstacle or a goal (m): an edit is small next to a room of several metres.
STEP = 0.5
#: Range of the factor a resize scales a footprint by.
SCALE = (0.75, 1.33)
#: Proposals an edit makes (each re-proved) before it gives up.
TRIES = 8
#: Density (kg/m^3) of an added obstacle's nominal mass, as the cluttered generator's.
DENSITY = 300.0
_DEFAULT_RANGES = {"box_size": (0.3, 1.0), "cylinder_radius": (0.1, 0.4), "obstacle_height": (0.5, 1.5)}


class EditedWorld(World):
    """A world changed by edits after it was generated; ``edits`` says how (plain dicts, oldest first).

    Its ``content_hash`` (and so ``world_id``) covers the edits as well, since a moved goal leaves the
    scene alone: two levels are the same only when their generator, parameters, seed and edits are.
    """

    def __init__(self, parent: World, scene: Scene, tasks: Sequence[Task], report, edits: Sequence[dict],
                 plan=None):
        super().__init__(parent.generator, parent.seed, parent.params, scene, tasks, parent.robot, report,
                         parent.attempts, parent.allow_infeasible)
        self.set_provenance(preset=parent.preset)
        self.edits: tuple[dict, ...] = tuple(edits)
        #: The plan the generator drew for the people (:mod:`worldgen.verify.rewalk`): a later edit walks them
        #: from it again. None in a world generated without people.
        self.people_plan = plan if plan is not None else getattr(parent, "people_plan", None)

    @cached_property
    def content_hash(self) -> str:
        # The generated world's own hash, through the cached_property on World (mypy reads it as the value).
        identity = {"world": World.content_hash.func(self),  # type: ignore[attr-defined]
                    "tasks": [_task_dict(t) for t in self.tasks], "edits": list(self.edits)}
        text = json.dumps(identity, sort_keys=True, separators=(",", ":"))
        return "sha256:" + hashlib.sha256(text.encode()).hexdigest()


def editable(world: World) -> Optional[str]:
    """None when ``world`` can be edited, else why not (one line)."""
    if world.scene.movers:
        return "it has movers or people, whose timed proofs follow the obstacles"
    if not world.feasibility.feasible:
        return "it is not proven feasible"
    return None


def edit_world(world: World, seed: int, ops: Sequence[str] = EDITS, tries: int = TRIES) -> Optional[EditedWorld]:
    """``world`` with one edit drawn from ``ops`` with the stream of ``seed``, proven feasible; None when
    ``world`` cannot be edited or no proposal of ``tries`` passed the checker."""
    unknown = [op for op in ops if op not in EDITS]
    if unknown or not ops:
        raise ParameterError(f"parameter 'edits' must name some of {', '.join(EDITS)}, got {list(ops)!r}")
    if editable(world) is not None:
        return None
    rng = edit_rng(seed)
    for _ in range(tries):
        edit = _propose(world, str(ops[int(rng.integers(len(ops)))]), rng)
        if edit is None:
            continue
        edited = _proven(world, [edit])
        if edited is not None:
            return edited
    return None


def replay_edits(world: World, edits: Sequence[dict]) -> EditedWorld:
    """``world`` with the recorded ``edits`` applied in order, each re-proved; ParameterError when one no
    longer applies or no longer passes (a record from another worldgen version). Among people, each edit is
    proved on the static scene and the people are walked and certified once, after the last (the settled
    world does not depend on the order: :mod:`worldgen.verify.rewalk`)."""
    out: World = world
    for k, edit in enumerate(edits):
        edited = _proven(out, [dict(edit)], walk=k == len(edits) - 1)
        if edited is None:
            among = " among its people re-walked" if people_plan(out) is not None else ""
            raise ParameterError(f"edit {edit!r} of world {world.world_id} does not give a feasible world{among}")
        out = edited
    if not isinstance(out, EditedWorld):
        raise ParameterError("parameter 'edits' must hold at least one edit")
    return out


def with_edits(world: World, edits: Sequence[dict]) -> Optional[EditedWorld]:
    """``world`` with all of ``edits`` applied, proven once at the end; None when one names nothing there or
    the result does not pass the checker. The same world :func:`replay_edits` rebuilds edit by edit."""
    return _proven(world, [dict(e) for e in edits])


def _proven(world: World, edits: list[dict], walk: bool = True) -> Optional[EditedWorld]:
    """``world`` with ``edits``, proven; among people, walked again and certified unless ``walk`` is False
    (an edit of a replay before its last, whose people the last one walks)."""
    scene, tasks = world.scene, world.tasks
    try:
        for edit in edits:
            scene, tasks = apply_edit(scene, tasks, edit)
    except (KeyError, ValueError, IndexError, TypeError):  # a record that names nothing here, or a bad value
        return None
    report = feasibility.check(scene, tasks, world.robot)  # static: it never reads the people
    if not report.feasible or any(p is None for p in report.paths):
        return None
    plan = people_plan(world)
    if walk and (plan is not None or scene.movers):
        scene, report = settle(world, plan, scene, tasks, report)
        if not report.feasible:  # the people left no way through: not a world to keep
            return None
    before = world.edits if isinstance(world, EditedWorld) else ()
    return EditedWorld(world, scene, tasks, report, before + tuple(edits), plan)


def apply_edit(scene: Scene, tasks: Sequence[Task], edit: dict) -> tuple[Scene, tuple[Task, ...]]:
    """The scene and tasks after one recorded edit (no check: :func:`edit_world` proves the result).
    ValueError when the edit names nothing there or puts an obstacle outside the bounds."""
    op = edit["op"]
    tasks = tuple(tasks)
    if op == "move_goal":
        k = int(edit["task"])
        t = tasks[k]
        goal = Pose(float(edit["x"]), float(edit["y"]), t.goal.z, t.goal.roll, t.goal.pitch, t.goal.yaw)
        return scene, tasks[:k] + (Task(t.id, t.spawn, goal, t.goal_tolerance),) + tasks[k + 1:]
    if op in ("remove_mover", "remove_person"):
        person, name = op == "remove_person", edit["person" if op == "remove_person" else "mover"]
        if not any(m.name == name and m.person == person for m in scene.movers):
            raise ParameterError(f"no {'person' if person else 'scripted mover'} named {name!r}")
        return scene.with_movers(m for m in scene.movers if m.name != name), tasks
    nodes = list(scene.nodes)
    if op == "add":
        node = _node(edit["name"], edit["shape"], float(edit["x"]), float(edit["y"]), float(edit["yaw"]),
                     Material(*edit["material"]))
        _inside(node, scene.bounds)
        return scene.with_nodes(nodes + [node]), tasks
    target = (lambda n: removable(scene, n)) if op == "remove" else _obstacle
    index = next((i for i, n in enumerate(nodes) if n.name == edit["node"] and target(n)), None)
    if index is None:
        raise ParameterError(f"no obstacle named {edit['node']!r}")
    old = nodes[index]
    if op == "remove":
        return scene.with_nodes(nodes[:index] + nodes[index + 1:]), tasks
    if op == "move":
        node = _node(old.name, _shape_dict(old.shape), float(edit["x"]), float(edit["y"]), old.pose.yaw, old.material)
    elif op == "resize":
        shape = _shape_dict(old.shape)
        factor = float(edit["factor"])
        if shape["type"] == "box":
            shape["size"] = [round_float(shape["size"][0] * factor), round_float(shape["size"][1] * factor),
                             shape["size"][2]]
        else:
            shape["radius"] = round_float(shape["radius"] * factor)
        node = _node(old.name, shape, old.pose.x, old.pose.y, old.pose.yaw, old.material)
    else:
        raise ParameterError(f"unknown edit {op!r}")
    _inside(node, scene.bounds)
    nodes[index] = node
    return scene.with_nodes(nodes), tasks


def _propose(world: World, op: str, rng: np.random.Generator) -> Optional[dict]:
    """One random edit of kind ``op`` as plain data, or None when ``world`` offers nothing to edit so."""
    scene = world.scene
    obstacles = [n for n in scene.nodes if _obstacle(n)]
    if op == "move_goal":
        k = int(rng.integers(len(world.tasks)))
        dx, dy = _slide(rng)
        task = world.tasks[k]
        x, y = round_float(task.goal.x + dx), round_float(task.goal.y + dy)
        if math.hypot(x - task.spawn.x, y - task.spawn.y) < float(world.params.get("min_spawn_goal_distance") or 0.0):
            return None  # the generator's own floor on the task's length holds for edits too
        return {"op": op, "task": k, "x": x, "y": y}
    if op == "add":
        (x0, y0), (x1, y1) = scene.bounds
        ranges = {k: tuple(world.params.get(k) or v) for k, v in _DEFAULT_RANGES.items()}
        height = round_float(rng.uniform(*ranges["obstacle_height"]))
        if rng.random() < 0.5:
            low, high = ranges["box_size"]
            sx, sy = (round_float(v) for v in rng.uniform(low, high, size=2))
            shape: dict = {"type": "box", "size": [sx, sy, height]}
            material = ("obstacle_box", (0.80, 0.52, 0.25, 1.0), float(world.params.get("friction", 1.0)))
        else:
            shape = {"type": "cylinder", "radius": round_float(rng.uniform(*ranges["cylinder_radius"])), "length": height}
            material = ("obstacle_cylinder", (0.25, 0.50, 0.75, 1.0), float(world.params.get("friction", 1.0)))
        taken = {n.name for n in scene.nodes}
        name = next(f"edit_obstacle_{i}" for i in range(len(taken) + 1) if f"edit_obstacle_{i}" not in taken)
        return {"op": op, "name": name, "shape": shape, "x": round_float(rng.uniform(x0, x1)),
                "y": round_float(rng.uniform(y0, y1)), "yaw": round_float(rng.uniform(-math.pi, math.pi)),
                "material": [material[0], list(material[1]), material[2]]}
    if not obstacles:
        return None
    node = obstacles[int(rng.integers(len(obstacles)))]
    if op == "remove":
        return {"op": op, "node": node.name}
    if op == "move":
        dx, dy = _slide(rng)
        return {"op": op, "node": node.name, "x": round_float(node.pose.x + dx), "y": round_float(node.pose.y + dy)}
    return {"op": op, "node": node.name, "factor": round_float(rng.uniform(*SCALE))}


def _slide(rng: np.random.Generator) -> tuple[float, float]:
    """A displacement uniform in the disc of radius :data:`STEP`."""
    r, a = STEP * math.sqrt(rng.random()), rng.uniform(-math.pi, math.pi)
    return r * math.cos(a), r * math.sin(a)


def removable(scene, node: Node) -> bool:
    """Whether shrinking may remove ``node``: a root obstacle that holds nothing (a mesh too)."""
    return node.role == "obstacle" and node.parent is None and not scene.children(node.name)


def _obstacle(node: Node) -> bool:
    return node.role == "obstacle" and node.parent is None and isinstance(node.shape, (Box, Cylinder))


def _shape_dict(shape) -> dict:
    if isinstance(shape, Box):
        return {"type": "box", "size": list(shape.size)}
    return {"type": "cylinder", "radius": shape.radius, "length": shape.length}


def _node(name: str, shape: dict, x: float, y: float, yaw: float, material: Material) -> Node:
    if shape["type"] == "box":
        sx, sy, sz = (float(v) for v in shape["size"])
        made: Any = Box((sx, sy, sz))
        height = made.size[2]
    else:
        made = Cylinder(float(shape["radius"]), float(shape["length"]))
        height, yaw = made.length, 0.0
    return Node(name, "obstacle", made, Pose(x, y, height / 2, 0.0, 0.0, yaw),
                mass=round_float(max(made.volume() * DENSITY, 1e-3)), material=material)


def _inside(node: Node, bounds) -> None:
    """ValueError when the node's floor shadow leaves the bounds (an obstacle stays on the floor)."""
    (x0, y0), (x1, y1) = bounds
    shape, pose = node.shape, node.pose
    if isinstance(shape, Cylinder):
        ex = ey = shape.radius
    else:
        assert isinstance(shape, Box)
        c, s = abs(math.cos(pose.yaw)), abs(math.sin(pose.yaw))
        hx, hy = shape.size[0] / 2, shape.size[1] / 2
        ex, ey = c * hx + s * hy, s * hx + c * hy
    if not (x0 + ex <= pose.x <= x1 - ex and y0 + ey <= pose.y <= y1 - ey):
        raise ParameterError(f"obstacle {node.name} would leave the floor")


def _task_dict(task: Task) -> dict:
    return {"id": task.id, "spawn": [task.spawn.x, task.spawn.y, task.spawn.yaw],
            "goal": [task.goal.x, task.goal.y, task.goal.yaw], "tolerance": task.goal_tolerance}
