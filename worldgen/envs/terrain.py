"""The robot on terrain: a base whose height and tilt follow the ground, for worlds with ramps, kerbs,
potholes and rough patches (docs/terrain.md).

The flat worlds' base (:mod:`worldgen.envs.robot`) slides in the plane a few millimetres over the floor
and never touches it, which is what keeps it cheap; it cannot climb. On terrain the same body, the same
three velocity servos (forward and lateral along the body's own axes, turn about its own z) and the
same joints x, y, yaw get three more: a slide along z and hinges for pitch and roll (after yaw, so yaw
stays the heading in the plane and :meth:`~worldgen.envs.robot.RobotModel.pose` reads what it read).
The body stands on :data:`FEET` frictionless spheres of radius :data:`FOOT` under its rim (ahead, behind
and to either side, the way a differential-drive base stands on two wheels and two casters), which touch
only the ground: gravity and those contacts alone set its height and tilt, while the servos drive it
along its heading. Frictionless, because the servos are what moves the body and holds it against
sliding down a slope or sideways off a cross-slope; with friction the feet would brake it.

The cylinder (the chassis) starts :attr:`~worldgen.scene.Robot.ground_clearance` above the ground
(at least :data:`~worldgen.envs.robot.FLOOR_GAP`) and reaches the robot's height; its contacts are
the environment's collisions as on flat ground: a wall, an obstacle, or the ground itself where a bend
or an edge is more than the chassis clears. The floor's slab and the pieces it is cut into around a
pothole are floor; the terrain's pieces are not.
"""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np
from lxml import etree

from worldgen.envs.lidar import VISUAL_GROUP
from worldgen.envs.robot import FLOOR_GAP, ROBOT, RobotModel, add_robot
from worldgen.errors import SceneError
from worldgen.floats import fmt, fmt_seq

__all__ = ["FOOT", "FEET", "TILT_DAMPING", "GROUND_AFFINITY", "ground_geoms", "floor_geoms", "add_base", "add_terrain_robot",
           "settle", "centre_height", "lidar_frame"]

#: Radius (m) of each foot: a sphere rolls onto a step edge as long as the edge is lower than its radius
#: (the contact's normal then has an upward part), so this is well above the largest step a robot may
#: climb by default (20 mm), as a wheel's radius is.
FOOT = 0.05
#: The feet: ahead, to the left, behind, to the right, each under the rim, a foot's radius in from it.
FEET = 4
#: Damping (N m s/rad) of the pitch and roll hinges: the body settles onto a new slope without rocking.
TILT_DAMPING = 5.0
#: contype/conaffinity bit only the feet and the ground share: the feet touch the ground and nothing else.
GROUND_AFFINITY = 2
# Names of the ground's pieces (worldgen.scene.ground): each terrain element's, and the floor's slab cut
# into prisms around a pothole, which stands in the floor's place.
_PIECE = re.compile(r"(terrain|floor)_[0-9]+")


def floor_geoms(root, floor_names) -> list[str]:
    """Names of a world's floor geoms in its MJCF ``root``: the floor entities' (``floor_names``) where the
    MJCF has them, and the prisms the slab is cut into around potholes, which stand in its place."""
    return sorted(g.get("name") for g in root.find("worldbody").findall("geom")
                  if g.get("name") in floor_names or (_PIECE.fullmatch(g.get("name") or "")
                                                      and g.get("name").startswith("floor_")))


def ground_geoms(root, floor_names) -> list[str]:
    """Names of a world's ground geoms in its MJCF ``root``: the floor's and the terrain's pieces."""
    return sorted(g.get("name") for g in root.find("worldbody").findall("geom")
                  if g.get("name") in floor_names or _PIECE.fullmatch(g.get("name") or ""))


def add_base(root, robot, v_range: tuple[float, float], w_max: float, terrain: bool, floor_names) -> list[str]:
    """Add the robot to an MJCF ``root`` for a :class:`~worldgen.scene.Robot` ``robot``: on ``terrain`` the
    terrain base, else :func:`~worldgen.envs.robot.add_robot`'s flat one, unchanged; the names of the floor's
    geoms (contacts with them are no collision) for :func:`~worldgen.envs.robot.compile_world`."""
    if not terrain:
        add_robot(root, robot.radius, robot.height, v_range, w_max)
        return sorted(floor_names)
    add_terrain_robot(root, robot.radius, robot.height, robot.ground_clearance, v_range, w_max, floor_names)
    return floor_geoms(root, floor_names)


def add_terrain_robot(root, radius: float, height: float, ground_clearance: float, v_range: tuple[float, float],
                      w_max: float, floor_names) -> None:
    """Add the terrain base to an MJCF ``<mujoco>`` lxml element (changed in place): the flat base of
    :func:`~worldgen.envs.robot.add_robot` with z, pitch and roll joints, its chassis raised to the
    ground clearance, and feet that touch only the ground (whose geoms get the feet's contact bit)."""
    add_robot(root, radius, height, v_range, w_max)
    bottom = max(float(ground_clearance), FLOOR_GAP)
    if height <= bottom:
        raise SceneError(f"robot height {height!r} m must exceed its ground clearance {bottom!r} m")
    half = (height - bottom) / 2.0
    body = root.find(f"worldbody/body[@name='{ROBOT}']")
    body.set("pos", fmt_seq((0.0, 0.0, bottom + half)))
    body.find("geom").set("size", fmt_seq((radius, half)))
    yaw = body.find(f"joint[@name='{ROBOT}_yaw']")
    slide_z = etree.Element("joint", name=f"{ROBOT}_z", type="slide", axis="0 0 1", limited="false")
    yaw.addprevious(slide_z)
    for axis, suffix in (("1 0 0", "roll"), ("0 1 0", "pitch")):  # each added right after yaw: pitch, then roll
        yaw.addnext(etree.Element("joint", name=f"{ROBOT}_{suffix}", type="hinge", axis=axis, limited="false",
                                  damping=fmt(TILT_DAMPING)))
    # The servos act at the feet's centres' height: a foot's contact pushes through its centre, so where an
    # edge holds a foot back the drive pushes level with it, as a wheel's traction acts at the ground,
    # instead of above it, which would pitch the body onto the edge.
    body.find("site").set("pos", fmt_seq((0.0, 0.0, -half - bottom + FOOT)))
    geom = body.find("geom")
    rim = radius - FOOT
    for k in range(FEET):
        a = 2.0 * math.pi * k / FEET
        foot = etree.Element("geom", name=f"{ROBOT}_foot_{k}", type="sphere", size=fmt(FOOT), mass="0",
                             pos=fmt_seq((round(rim * math.cos(a), 9), round(rim * math.sin(a), 9),
                                          -half - bottom + FOOT)),
                             condim="1", priority="1", contype=str(GROUND_AFFINITY), conaffinity="0")
        geom.addnext(foot)
        geom = foot
    ground = set(ground_geoms(root, floor_names))
    for g in root.find("worldbody").findall("geom"):
        if g.get("name") in ground:
            g.set("conaffinity", str(int(g.get("conaffinity", "1")) | GROUND_AFFINITY))


def settle(sim: RobotModel, robot) -> float:
    """Stand the compiled terrain base of ``robot`` (a :class:`~worldgen.scene.Robot`) on the ground under its
    spawn: its z joint at the ground's height there (a ray straight down; 0 on the flat floor, where every
    generator puts spawns). Its centre's height over flat ground (:func:`centre_height`)."""
    import mujoco

    model, data = sim.model, sim.data
    x, y, _ = sim.pose()
    mujoco.mj_kinematics(model, data)
    top = float(data.xpos[sim.body][2]) + 10.0
    hit = np.zeros(1, np.int32)
    groups = np.ones(6, dtype=np.uint8)
    groups[VISUAL_GROUP] = 0  # markers are not ground
    depth = mujoco.mj_ray(model, data, np.array([x, y, top]), np.array([0.0, 0.0, -1.0]), groups, 1, sim.body, hit)
    if depth >= 0:
        data.qpos[model.joint(f"{ROBOT}_z").qposadr[0]] = top - depth
    mujoco.mj_forward(model, data)
    return centre_height(robot.height, robot.ground_clearance)


def centre_height(height: float, ground_clearance: float) -> float:
    """Height (m) of the terrain base's centre over flat ground: midway up its chassis."""
    return (float(height) + max(float(ground_clearance), FLOOR_GAP)) / 2.0


def lidar_frame(sim: RobotModel, lidar_height: float, centre: float) -> tuple[Any, Any]:
    """(origin, rotation) of a lidar ``lidar_height`` above the ground on the robot, carried and tilted with
    its body, whose centre stands ``centre`` over flat ground (:func:`centre_height`)."""
    data = sim.data
    rotation = data.xmat[sim.body].reshape(3, 3)
    return data.xpos[sim.body] + rotation[:, 2] * (lidar_height - centre), rotation
