"""Scene -> ``hunav_agents.yaml``: the world's crowd as the agents file HuNavSim loads (docs/hunav.md).

A ROS 2 parameters file of the node ``hunav_loader`` (robotics-upo/hunav_sim,
``hunav_agent_manager/src/hunav_loader.cpp``, which declares each parameter with its type; the Gazebo
wrapper's ``WorldGenerator`` reads them back from that node and needs every one):

* ``map``: the world's nav2 map beside this file (map.yaml; HuNavSim reads the name, the simulator holds
  the walls); ``publish_people``: true, so its agents are also on ``/people``; ``agents``: the names.
* per agent: ``id`` (1, 2, ... in order), ``skin`` (one of its five Gazebo models, in turn), ``behavior``
  (:data:`BEHAVIOR`: HuNavSim's number for the person's behaviour, world.json's ``people[].behaviour``,
  impassive where absent), ``group_id`` (the index of the first member of the person's group, which
  walked together under a group force as HuNavSim's groups do; -1 alone), ``max_vel`` (m/s, the walk's pace,
  :func:`worldgen.export.crowd.walking_speed`), ``radius`` (m), ``init_pose`` (x, y at the first row, z
  :data:`SKIN_Z`, h the heading of the first leg, rad), ``goal_radius`` (the radius, m), ``cyclic_goals``
  (false for a person, who walks once and stands; true for a scripted mover, which loops) and ``goals``,
  the corners of world.json's walk (:mod:`worldgen.export.crowd`), each with x, y and h, the heading it
  arrives in (rad).

rclcpp types a parameter by its text: an integer where ``strtol`` reads it whole, else a double where
``strtod`` does, and declaring a double from an integer's text is an error. So every double here has a
decimal point (``2.0``, never ``2``).
"""

from __future__ import annotations

import math
from typing import Sequence

from worldgen.export.crowd import agents, people_args
from worldgen.files import MAP_YAML_NAME
from worldgen.floats import fmt
from worldgen.scene import Scene

__all__ = ["to_hunav", "writer_args", "BEHAVIOR", "SKINS", "SKIN_Z", "NODE"]

#: HuNavSim's behaviour numbers (hunav_msgs/msg/Agent.msg ``BEH_*``) by worldgen's names, which are its own.
BEHAVIOR = {"regular": 1, "impassive": 2, "surprised": 3, "scared": 4, "curious": 5}
#: How many skins (3-D models) its Gazebo wrapper offers agents (0 to 4, its README).
SKINS = 5
#: init_pose.z (m): where HuNavSim's own agents files put its skins' origin above the floor.
SKIN_Z = 1.25
#: The node whose parameters the file sets.
NODE = "hunav_loader"


def writer_args(world) -> dict:
    """What :func:`to_hunav` reads off a World besides its scene."""
    return people_args(world)


def _double(x: float) -> str:
    text = fmt(x)
    return text if "." in text else text + ".0"


def _heading(a, b) -> float:
    return math.atan2(b[1] - a[1], b[0] - a[0]) if (a[0], a[1]) != (b[0], b[1]) else 0.0


def to_hunav(scene: Scene, name: str = "default", behaviours: Sequence[str] = (), groups: Sequence[int] = ()) -> bytes:
    """HuNavSim's agents file for ``scene``'s people and movers (UTF-8 bytes); see the module docstring.
    ``behaviours``, ``groups``: each person's (world.json's ``people[].behaviour``; the params' groups,
    :func:`worldgen.people.places.group_ids`). A scene without people is a ParameterError."""
    crowd = agents(scene, "hunav", behaviours, groups)
    out = [f"# worldgen world {name}: its people and movers for HuNavSim (docs/hunav.md)",
           f"{NODE}:", "  ros__parameters:", f"    map: {MAP_YAML_NAME}", "    publish_people: true", "    agents:"]
    out += [f"      - {agent.name}" for agent in crowd]
    for k, agent in enumerate(crowd):
        out += [f"    {agent.name}:", f"      id: {k + 1}", f"      skin: {k % SKINS}",
                f"      behavior: {BEHAVIOR[agent.behaviour]}", f"      group_id: {agent.group}",
                f"      max_vel: {_double(agent.speed)}", f"      radius: {_double(agent.radius)}",
                "      init_pose:", f"        x: {_double(agent.start[0])}", f"        y: {_double(agent.start[1])}",
                f"        z: {_double(SKIN_Z)}", f"        h: {_double(agent.heading)}",
                f"      goal_radius: {_double(agent.radius)}", f"      cyclic_goals: {'true' if agent.loop else 'false'}",
                "      goals:"]
        goals = agent.goals.tolist()
        out += [f"        - g{j}" for j in range(len(goals))]
        before = agent.start
        for j, (x, y) in enumerate(goals):
            out += [f"      g{j}:", f"        x: {_double(x)}", f"        y: {_double(y)}",
                    f"        h: {_double(_heading(before, (x, y)))}"]
            before = (x, y)
    return ("\n".join(out) + "\n").encode()
