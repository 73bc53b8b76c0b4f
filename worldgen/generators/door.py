"""``door``: rooms in a row, divided by walls whose doorways hold leaves on revolute hinges.

The building is ``size`` (x, y), centred on the origin and walled round; the
``n_doors`` dividing walls run across it (along y) at ``door_x`` and evenly
beyond it (or evenly over the whole length when ``door_x`` is unset), so rooms
follow each other along +x. Each dividing wall has one doorway of
``door_width``, framed by two jambs and a head (role ``door_frame``); the leaf
(role ``door``, a dynamic box) hangs from the head on a revolute joint with
``limits`` and ``door_damping``, starting ``closed``, ``open`` or ``ajar``.

Geometry, with the travel direction +x (spawn in the first room, goal in the
last): ``hinge_side`` left puts the hinge at the doorway's +y edge; ``swing``
push opens the leaf towards +x. The hinge line sits on the wall face of the
side the leaf opens into, so the leaf, closed, fills the doorway inside the wall
thickness and, opening, sweeps only that side's room (up to ``limits`` hi <= 3
rad, short of lying flat against the wall). Positive angles open the door in
every format; world.json's ``doors[]`` says where (see :mod:`worldgen.scene.doors`).

A leaf opens only as far as its room lets it: past pi/2 its free edge comes
back towards the outer wall on the hinge side, and a thick leaf's corner
reaches furthest into the room a little past pi/2. Where a wall would stop the
leaf before ``limits`` hi, that door's upper limit is the angle at which the
leaf stays ``LEAF_GAP`` short of it (a door stop); world.json's ``doors[].limits``
and every format carry that door's own limits. An ``ajar`` angle or a lower
limit the room cannot hold rejects the draw (a fixed ``door_y``: one line).
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np

from worldgen.errors import ParameterError
from worldgen.floats import round_float
from worldgen.generators.base import Draft, GeneratorSpec, robot_from_params
from worldgen.generators.knob import Knob
from worldgen.generators.room import WALL_RGBA, floor_node, wall_nodes
from worldgen.generators.tasks import free_points
from worldgen.params import Param
from worldgen.scene import Box, Joint, Material, Node, Physics, Pose, Scene, Task, matrix_to_pose
from worldgen.scene.doors import swept_scenes
from worldgen.scene.footprint import FootprintIndex, robot_footprints

__all__ = ["SPEC", "build", "check", "wall_positions", "LEAF_GAP", "JAMB_WIDTH", "MAX_OPENING"]

#: Gap (m) between the leaf and the jambs, the floor and the head: the leaf never rubs the frame.
LEAF_GAP = 0.01
#: Width (m) of each jamb along the wall.
JAMB_WIDTH = 0.05
#: Largest opening limit (rad): at pi the leaf would lie on the wall face, touching it.
MAX_OPENING = 3.0
#: Smallest head (lintel) above the doorway, m.
MIN_HEAD = 0.05

LEAF_RGBA = (0.62, 0.42, 0.24, 1.0)
FRAME_RGBA = (0.35, 0.30, 0.26, 1.0)

PARAMS = (
    Param("size", "pair", [8.0, 4.0], "inner extents (x, y) of the whole building, centred on the origin", 1.0, 500.0, unit="m"),
    Param("n_doors", "int", 1, "dividing walls (one door each) in sequence along x", 1, 16),
    Param("door_x", "float", None, "x of the first dividing wall (the rest evenly beyond it); unset: all evenly spaced",
          -250.0, 250.0, optional=True, unit="m"),
    Param("door_y", "float", None, "y of every doorway's centre; unset: drawn per door", -250.0, 250.0, optional=True, unit="m"),
    Param("door_width", "float", 0.9, "clear width of each doorway (the leaf is 2 cm narrower)", 0.1, 20.0, unit="m"),
    Param("door_height", "float", 2.0, "height of each doorway", 0.1, 50.0, unit="m"),
    Param("leaf_thickness", "float", 0.04, "thickness of each door leaf", 0.005, 1.0, unit="m"),
    Param("leaf_mass", "float", 15.0, "mass of each door leaf", 0.1, 1000.0, unit="kg"),
    Param("door_damping", "float", 5.0, "hinge damping, so a pushed door comes to rest", 0.0, 1000.0, unit="N m s/rad"),
    Param("hinge_side", "choice", "left", "hinge on the left or right edge looking along +x, or drawn per door",
          choices=("left", "right", "random")),
    Param("swing", "choice", "push", "leaf opens away from the spawn side (push, towards +x) or towards it (pull), or drawn",
          choices=("push", "pull", "random")),
    Param("limits", "range", [0.0, 1.570796], "opening range of the hinge (0 = closed; positive opens; default about pi/2)",
          0.0, MAX_OPENING, unit="rad"),
    Param("state", "choice", "closed", "how every door starts (random: drawn per door)",
          choices=("closed", "open", "ajar", "random")),
    Param("angle", "float", 0.5, "initial opening angle of an ajar door, strictly inside limits", 0.0, MAX_OPENING, unit="rad"),
    Param("wall_height", "float", 2.5, "height of all walls", 0.1, 50.0, unit="m"),
    Param("wall_thickness", "float", 0.1, "thickness of all walls", 0.01, 10.0, unit="m"),
    Param("spawn", "triple", None, "fix the first task's spawn pose [x, y, yaw] instead of drawing it in the first room",
          -10000.0, 10000.0, optional=True, unit="m, m, rad"),
    Param("goal", "pair", None, "fix the first task's goal [x, y] instead of drawing it in the last room",
          -10000.0, 10000.0, optional=True, unit="m"),
)


def wall_positions(params: Mapping[str, Any]) -> list[float]:
    """x of each dividing wall's centre line."""
    sx = params["size"][0]
    n = params["n_doors"]
    x0, x1 = -sx / 2, sx / 2
    if params["door_x"] is None:
        return [x0 + (k + 1) * sx / (n + 1) for k in range(n)]
    first = params["door_x"]
    step = (x1 - first) / n
    return [first + k * step for k in range(n)]


def _room_spans(params) -> list[tuple[float, float]]:
    """(x start, x end) of each room's floor between wall faces."""
    sx = params["size"][0]
    t = params["wall_thickness"]
    xs = wall_positions(params)
    edges = [-sx / 2] + [v for x in xs for v in (x - t / 2, x + t / 2)] + [sx / 2]
    return [(edges[2 * k], edges[2 * k + 1]) for k in range(len(xs) + 1)]


def check(params: Mapping[str, Any]) -> None:
    """Reject combinations no draw could build, naming the parameter and the allowed range."""
    sx, sy = params["size"]
    w = params["door_width"]
    inflation = params["robot_radius"] + params["clearance"]
    lo, hi = params["limits"]
    if hi - lo <= 0:
        raise ParameterError(f"parameter 'limits' must be [lo, hi] with lo < hi in [0, {MAX_OPENING:g}] rad, "
                             f"got {params['limits']!r}")
    if params["state"] in ("closed", "random") and lo != 0:
        raise ParameterError(f"parameter 'limits' must start at 0 (closed) for state {params['state']}, got {params['limits']!r}")
    if params["state"] in ("ajar", "random") and not lo < params["angle"] < hi:
        raise ParameterError(f"parameter 'angle' must lie strictly inside limits ({lo:g}, {hi:g}) rad for an ajar door, "
                             f"got {params['angle']!r}")
    if params["door_height"] > params["wall_height"] - MIN_HEAD:
        raise ParameterError(f"parameter 'door_height' must be in [0.1, {params['wall_height'] - MIN_HEAD:g}] m "
                             f"(wall_height - {MIN_HEAD:g}), got {params['door_height']!r}")
    if params["robot_height"] + params["clearance"] > params["door_height"]:
        # The footprint passes under a doorway's head only with its clearance to spare (FCL measures in 3-D).
        raise ParameterError(
            f"parameter 'robot_height' must be at most door_height - clearance = "
            f"{params['door_height'] - params['clearance']:g} m to pass under the doorways, got {params['robot_height']!r}")
    if params["robot_height"] >= params["door_height"]:
        # With no clearance asked, a robot exactly as tall as the opening would touch the head: FCL, MuJoCo
        # and the oracles all count touching as a contact, so the world would not be what it claims.
        raise ParameterError(
            f"parameter 'robot_height' must be below door_height = {params['door_height']:g} m (a robot as tall as "
            f"the doorway touches its head), got {params['robot_height']!r}")
    if params["door_height"] - 2 * LEAF_GAP <= 0:
        raise ParameterError(f"parameter 'door_height' must exceed {2 * LEAF_GAP:g} m, got {params['door_height']!r}")
    room = sy - 2 * JAMB_WIDTH
    if w - 2 * LEAF_GAP <= 0 or w > room:
        raise ParameterError(f"parameter 'door_width' must be in ({2 * LEAF_GAP:g}, {room:g}] m for size y {sy:g} m "
                             f"(two {JAMB_WIDTH:g} m jambs), got {w!r}")
    if params["door_y"] is not None and abs(params["door_y"]) > (room - w) / 2:
        raise ParameterError(f"parameter 'door_y' must be in [{-(room - w) / 2:g}, {(room - w) / 2:g}] m for this "
                             f"size and door_width, got {params['door_y']!r}")
    if params["door_x"] is not None and not -sx / 2 < params["door_x"] < sx / 2:
        raise ParameterError(f"parameter 'door_x' must be in ({-sx / 2:g}, {sx / 2:g}) m (inside size x), "
                             f"got {params['door_x']!r}")
    need = max(2 * inflation, w) + 2 * LEAF_GAP  # the robot, and a leaf opening into the room
    for k, (a, b) in enumerate(_room_spans(params)):
        if b - a < need:
            what = "door_x" if params["door_x"] is not None else "size"
            raise ParameterError(
                f"parameter '{what}' leaves room {k} {b - a:.3f} m long; every room needs >= {need:g} m "
                f"(max(2 x (robot_radius + clearance), door_width) + {2 * LEAF_GAP:g}), got {params[what]!r}")
    r = inflation
    for name in ("spawn", "goal"):
        value = params.get(name)
        if value is not None and not (-sx / 2 + r <= value[0] <= sx / 2 - r and -sy / 2 + r <= value[1] <= sy / 2 - r):
            raise ParameterError(
                f"parameter '{name}' must keep the robot's {r:g} m disc on the floor, i.e. x in "
                f"[{-sx / 2 + r:g}, {sx / 2 - r:g}] and y in [{-sy / 2 + r:g}, {sy / 2 - r:g}], got {value!r}")
    spawn = params.get("spawn")
    if spawn is not None and not -math.pi <= spawn[2] <= math.pi:
        raise ParameterError(f"parameter 'spawn' yaw (third value) must be in [-pi, pi] rad, got {spawn!r}")


def swing_stop(lw: float, lt: float, beside: float, ahead: float) -> float:
    """Largest opening angle (rad, at most pi) of a ``lw`` x ``lt`` leaf that stays LEAF_GAP off the walls.

    The leaf turns about its hinge, which sits on the wall face; ``beside`` is the
    free wall face from the hinge to the wall across its path on the hinge side,
    ``ahead`` the room's length in front of the wall face. At angle a, the leaf
    reaches ``-lw cos a`` along the wall face beside the hinge and
    ``lw sin a - lt cos a`` into the room (its far corners).
    """
    stop = math.pi
    u = beside - LEAF_GAP
    if u < lw:  # past pi/2 the free edge comes back along the wall face
        stop = min(stop, math.acos(max(-1.0, -u / lw)))
    reach, tilt = math.hypot(lw, lt), math.atan2(lt, lw)
    v = ahead - LEAF_GAP
    if v < reach:  # lw sin a - lt cos a = reach sin(a - tilt) <= v
        stop = min(stop, tilt + math.asin(max(-1.0, v / reach)))
    return math.floor(stop * 1e6) / 1e6  # rounded down: world.json's 6 decimals never open it further


def build(params: Mapping[str, Any], rng: np.random.Generator) -> Draft:
    door_rng, task_rng = rng.spawn(2)
    sx, sy = params["size"]
    h_w, t = params["wall_height"], params["wall_thickness"]
    friction = params["friction"]
    bounds = ((-sx / 2, -sy / 2), (sx / 2, sy / 2))
    nodes = [floor_node(params["size"], t, friction)]
    nodes += wall_nodes(params["size"], h_w, t, friction)
    joints = []
    rooms = _room_spans(params)
    for k, x in enumerate(wall_positions(params)):
        # Always draw the same four numbers per door, so fixing one choice never reshuffles the rest.
        u_side, u_swing, u_state, u_y = door_rng.random(4)
        door_nodes, joint = _door(params, k, x, u_side, u_swing, u_state, u_y, rooms)
        if isinstance(joint, str):
            return Draft(None, rejected="door_swing", detail=joint)
        nodes += door_nodes
        joints.append(joint)
    scene = Scene(tuple(nodes), tuple(joints), bounds, Physics(params["step_size"], params["real_time_factor"]))
    robot = robot_from_params(params)
    # Spawns and goals must be free with the doors as they start, as they open and everywhere in between: a
    # robot waiting on a leaf's sweep would be pushed by the leaf opening onto it (benchmark door seed 171).
    sweep = swept_scenes(scene, robot.inflation) or [scene]
    index = FootprintIndex([fp for at in sweep for fp in robot_footprints(at, robot)])
    first = ((rooms[0][0], -sy / 2), (rooms[0][1], sy / 2))
    last = ((rooms[-1][0], -sy / 2), (rooms[-1][1], sy / 2))
    tasks, reason = _tasks(params, task_rng, index, first, last, robot)
    if reason:
        return Draft(scene, rejected="task_placement", detail=reason)
    return Draft(scene, tuple(tasks))


def _pick(u: float, value: str, options: tuple[str, ...]) -> str:
    return options[min(int(u * len(options)), len(options) - 1)] if value == "random" else value


def _door(params, k: int, x: float, u_side, u_swing, u_state, u_y, rooms):
    """Nodes (wall pieces, jambs, head, leaf) and the hinge of dividing wall ``k`` at ``x``.

    Instead of the hinge, the reason when this door's room cannot hold its initial angle.
    """
    sy = params["size"][1]
    w, t, h_w = params["door_width"], params["wall_thickness"], params["wall_height"]
    d_h, lt = params["door_height"], params["leaf_thickness"]
    friction = params["friction"]
    half_room = (sy - 2 * JAMB_WIDTH - w) / 2
    c = params["door_y"] if params["door_y"] is not None else round_float(-half_room + 2 * half_room * u_y)
    h = 1 if _pick(u_side, params["hinge_side"], ("left", "right")) == "left" else -1
    s = 1 if _pick(u_swing, params["swing"], ("push", "pull")) == "push" else -1
    state = _pick(u_state, params["state"], ("closed", "open", "ajar"))
    lw, lh = w - 2 * LEAF_GAP, d_h - 2 * LEAF_GAP
    hx, hy = x + s * t / 2, c + h * (w / 2 - LEAF_GAP)
    room = rooms[k + 1] if s > 0 else rooms[k]
    lo, hi = params["limits"]
    hi = min(hi, swing_stop(lw, lt, sy / 2 - h * hy, room[1] - room[0]))
    initial = {"closed": 0.0, "open": hi, "ajar": params["angle"]}[state]
    if not lo < hi or (state == "ajar" and not initial < hi):
        return [], (f"door {k}'s room stops its leaf at {hi:g} rad, short of its "
                    f"{'ajar angle' if state == 'ajar' else 'lower limit'} ({initial if state == 'ajar' else lo:g} rad)")

    wall_mat = Material("wall", WALL_RGBA, friction)
    frame_mat = Material("door_frame", FRAME_RGBA, friction)
    nodes = []
    # Wall pieces from the outer walls to the jambs (none where a jamb reaches the outer wall).
    south = (-sy / 2, c - w / 2 - JAMB_WIDTH)
    north = (c + w / 2 + JAMB_WIDTH, sy / 2)
    for label, (a, b) in (("s", south), ("n", north)):
        if b - a > 1e-6:
            nodes.append(Node(f"wall_{k}_{label}", "wall", Box((t, b - a, h_w)), Pose(x, (a + b) / 2, h_w / 2),
                              material=wall_mat))
    for label, y in (("s", c - w / 2 - JAMB_WIDTH / 2), ("n", c + w / 2 + JAMB_WIDTH / 2)):
        nodes.append(Node(f"door_{k}_jamb_{label}", "door_frame", Box((t, JAMB_WIDTH, h_w)), Pose(x, y, h_w / 2),
                          material=frame_mat))
    # The head spans the doorway; its local +y points to the side the leaf opens into.
    head = Node(f"door_{k}_head", "door_frame", Box((w, t, h_w - d_h)),
                Pose(x, c, d_h + (h_w - d_h) / 2, 0.0, 0.0, -s * math.pi / 2), material=frame_mat)
    nodes.append(head)
    closed = Pose(hx - s * lt / 2, hy - h * lw / 2, LEAF_GAP + lh / 2, 0.0, 0.0, -h * math.pi / 2)
    hinge = Pose(-lw / 2, s * h * lt / 2, 0.0)
    axis = (0.0, 0.0, float(s * h))
    # The leaf at its initial angle, then expressed in the head's frame (the scene stores parent-relative poses).
    j = hinge.matrix()
    turn = np.eye(4)
    turn[:3, :3] = Pose(yaw=s * h * initial).rotation
    world = closed.matrix() @ j @ turn @ np.linalg.inv(j)
    leaf_pose = matrix_to_pose(np.linalg.inv(head.pose.matrix()) @ world)
    leaf = Node(f"door_{k}", "door", Box((lw, lt, lh)), leaf_pose, parent=head.name, static=False,
                mass=params["leaf_mass"], material=Material("door_leaf", LEAF_RGBA, friction))
    nodes.append(leaf)
    joint = Joint(f"door_{k}_hinge", "revolute", head.name, leaf.name, pose=hinge, axis=axis,
                  limits=(lo, hi), initial=initial, damping=params["door_damping"])
    return nodes, joint


def _tasks(params, rng, index, first, last, robot):
    """Spawns in the first room, goals in the last (or the fixed ones); returns (tasks, reason)."""
    separation = 2 * robot.inflation
    spawns, goals = [], []
    fixed_spawn, fixed_goal = params.get("spawn"), params.get("goal")
    for label, fixed in (("spawn", fixed_spawn), ("goal", fixed_goal)):
        if fixed is not None and index.blocked(np.array([fixed[:2]], dtype=float), robot.inflation + 1e-3)[0]:
            return [], f"the fixed {label} ({fixed[0]:g}, {fixed[1]:g}) is not free for a {robot.inflation:g} m disc"
    n = params["n_tasks"]
    for pts, region, out, fixed in ((spawns, first, spawns, fixed_spawn), (goals, last, goals, fixed_goal)):
        if fixed is not None:
            out.append((float(fixed[0]), float(fixed[1])))
        for _ in range(16):
            if len(out) == n:
                break
            for p in free_points(rng, index, region, robot, 64):
                if len(out) < n and all(math.hypot(p[0] - q[0], p[1] - q[1]) >= separation for q in out):
                    out.append((float(p[0]), float(p[1])))
        if len(out) < n:
            which, room = ("spawns", "first") if out is spawns else ("goals", "last")
            return [], f"found {len(out)} of {n} free {which} in the {room} room"
    yaws = rng.uniform(-math.pi, math.pi, 2 * n)
    tasks = []
    for i in range(n):
        spawn_yaw = round_float(fixed_spawn[2]) if i == 0 and fixed_spawn is not None else round_float(yaws[2 * i])
        tasks.append(Task(f"task_{i}", Pose(*spawns[i], 0.0, 0.0, 0.0, spawn_yaw),
                          Pose(*goals[i], 0.0, 0.0, 0.0, round_float(yaws[2 * i + 1])), params["goal_tolerance"]))
    return tasks, None


SPEC = GeneratorSpec(
    name="door",
    summary="rooms in a row, divided by walls with hinged door leaves (closed, open or ajar)",
    params=PARAMS,
    build=build,
    check=check,
    examples=(
        "worldgen generate door --seed 1 --set n_doors=2 --set state=closed --out worlds",
        "worldgen generate door --set size=14,4 --set door_x=3 --set door_y=0 --set spawn=0,0,0 --set goal=6,0 --out worlds",
    ),
    # Levels: open doors (rooms in a row) up to level 5, closed leaves to push from level 6. Level 1 is out
    # of reach: no request with seeds 100-109 landed there (docs/metrics.md).
    knob=Knob("n_doors", (None, 1, 1, 1, 1, 1, 1, 1, 2, 4), step=1.0, high=5.0, low=1.0,
              fixed=((1, 5, {"state": "open"}), (6, 10, {"state": "closed"}))),
)
