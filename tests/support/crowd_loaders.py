"""The loaders of pedsim_simulator's scenario file and HuNavSim's agents file, re-written from their source as
checkers: every rule their code holds a file to, and what they would read out of it.

Neither tool runs here (both are ROS packages), so these are the references, written from:

* pedsim: ``pedsim_simulator/src/scenarioreader.cpp`` (srl-freiburg/pedsim_ros master, the same element and
  attribute names in ignc-research/pedsim_ros, the fork of the Arena stack, on every branch). A
  ``QXmlStreamReader`` walks the start elements in document order; each known element's attributes are read
  with ``QString::toDouble`` / ``toInt``, which give 0 for a missing or malformed value without a word, so
  here a missing or malformed attribute fails. ``<addwaypoint>`` acts on the ``<agent>`` (or ``<source>``)
  being read and looks its id up at once (``SCENE.getWaypointByName``): the waypoint must come before. An
  unknown element is skipped by the reader (a debug message); here it fails, since we never mean one.
  Agent types: ``Ped::Tagent::AgentType``, ADULT 0 and CHILD 1 in both forks; the robot is 2 in
  srl-freiburg's and 5 in ignc-research's (where 2 is ELDER). Waypoint behaviours: SIMPLE 0, SOURCE 1, SINK 2.
* HuNavSim: ``hunav_agent_manager/src/hunav_loader.cpp`` (robotics-upo/hunav_sim, humble), which declares each
  parameter with its C++ type, and hunav_gazebo_wrapper's ``WorldGenerator``, which reads every one of them
  back (``as_int``, ``as_double``, ``as_bool``, ``as_string_array``: a parameter not set is an exception
  there). rclcpp types a scalar by its text (an integer where strtol reads it whole, a double where strtod
  does), and declaring a double from an integer's text is an error; for the plain numbers a file of ours
  holds, that is how YAML types them, so the types are YAML's. A string array may not be empty (an empty
  sequence has no type). Behaviours: ``hunav_msgs/msg/Agent.msg``; skins 0 to 4 (its README).
"""

from __future__ import annotations

import re

import yaml
from lxml import etree

__all__ = ["read_pedsim", "read_hunav", "PEDSIM_PERSON_TYPES", "HUNAV_BEHAVIORS"]

#: The agent types that are a person in both pedsim forks (ADULT, CHILD).
PEDSIM_PERSON_TYPES = (0, 1)
#: hunav_msgs/msg/Agent.msg's BEH_* constants.
HUNAV_BEHAVIORS = {"regular": 1, "impassive": 2, "surprised": 3, "scared": 4, "curious": 5, "threatening": 6}

_DOUBLE = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")
_INT = re.compile(r"[+-]?\d+")
#: What the reader reads of each element it knows: attribute -> "double" | "int" | "id".
_PEDSIM = {
    "scenario": {}, "welcome": {},
    "obstacle": {"x1": "double", "y1": "double", "x2": "double", "y2": "double"},
    "waypoint": {"id": "id", "x": "double", "y": "double", "r": "double", "b": "int"},
    "queue": {"id": "id", "x": "double", "y": "double", "direction": "double"},
    "attraction": {"id": "id", "x": "double", "y": "double", "width": "double", "height": "double", "strength": "double"},
    "agent": {"x": "double", "y": "double", "n": "int", "dx": "double", "dy": "double", "type": "int"},
    "source": {"x": "double", "y": "double", "n": "int", "dx": "double", "dy": "double", "type": "int"},
    "addwaypoint": {"id": "id"}, "addqueue": {"id": "id"},
}


def _attrs(element, where: str) -> dict:
    out = {}
    for name, kind in _PEDSIM[element.tag].items():
        text = element.get(name)
        assert text is not None, f"{where}: <{element.tag}> has no {name} (the reader would take 0 or '')"
        if kind == "double":
            assert _DOUBLE.fullmatch(text), f"{where}: <{element.tag} {name}={text!r}> is no number for toDouble"
            out[name] = float(text)
        elif kind == "int":
            assert _INT.fullmatch(text), f"{where}: <{element.tag} {name}={text!r}> is no integer for toInt"
            out[name] = int(text)
        else:
            assert text, f"{where}: <{element.tag}> has an empty {name}"
            out[name] = text
    return out


def read_pedsim(data: bytes) -> dict:
    """What pedsim_simulator reads out of a scenario file: ``obstacles`` [(x1, y1, x2, y2)], ``waypoints``
    {id: {x, y, r, b}}, ``agents`` [{x, y, n, dx, dy, type, route: [waypoint ids]}]; AssertionError naming
    the element for a file its reader would misread."""
    parser = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False)
    root = etree.fromstring(data, parser)
    assert root.tag == "scenario", f"the root is <{root.tag}>, the reader's scenario is <scenario>"
    out: dict = {"obstacles": [], "waypoints": {}, "agents": []}
    for element in root.iter():
        if not isinstance(element.tag, str):  # a comment
            continue
        where = f"line {element.sourceline}"
        assert element.tag in _PEDSIM, f"{where}: <{element.tag}> is no element the reader knows"
        a = _attrs(element, where)
        if element.tag == "obstacle":
            out["obstacles"].append((a["x1"], a["y1"], a["x2"], a["y2"]))
        elif element.tag == "waypoint":
            assert a["id"] not in out["waypoints"], f"{where}: a second waypoint {a['id']!r}"
            assert a["b"] in (0, 1, 2), f"{where}: waypoint behaviour {a['b']} is none of SIMPLE, SOURCE, SINK"
            assert a["r"] > 0, f"{where}: waypoint {a['id']!r} of radius {a['r']} is reached only exactly"
            out["waypoints"][a["id"]] = {k: a[k] for k in ("x", "y", "r", "b")}
        elif element.tag in ("agent", "source"):
            assert a["n"] >= 1, f"{where}: an agent cluster of {a['n']} agents"
            assert a["type"] in PEDSIM_PERSON_TYPES, f"{where}: agent type {a['type']} is not a person in both forks"
            out["agents"].append(a | {"route": []})
        elif element.tag == "addwaypoint":
            parent = element.getparent()
            assert parent is not None and parent.tag in ("agent", "source"), \
                f"{where}: <addwaypoint> outside an <agent> is dropped by the reader"
            assert a["id"] in out["waypoints"], f"{where}: waypoint {a['id']!r} is not read yet (define it before)"
            out["agents"][-1]["route"].append(a["id"])
    return out


_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_AGENT = {"id": int, "skin": int, "behavior": int, "group_id": int, "max_vel": float, "radius": float,
          "goal_radius": float, "cyclic_goals": bool}


def _typed(value, kind, where: str):
    if kind is float:
        assert isinstance(value, float), f"{where} = {value!r}: declared a double, so its text needs a decimal point"
    elif kind is int:
        assert isinstance(value, int) and not isinstance(value, bool), f"{where} = {value!r}: declared an integer"
    else:
        assert isinstance(value, kind), f"{where} = {value!r}: declared a {kind.__name__}"
    return value


def _names(value, where: str) -> list:
    assert isinstance(value, list) and value, f"{where} must be a non-empty string array (an empty one has no type)"
    for name in value:
        assert isinstance(name, str) and _NAME.fullmatch(name), f"{where}: {name!r} is no parameter name"
    assert len(set(value)) == len(value), f"{where} names one twice"
    return value


def read_hunav(text: str) -> dict:
    """What hunav_loader declares from an agents file (and the Gazebo wrapper reads back): ``map``,
    ``publish_people``, ``agents`` [{name, id, skin, behavior, group_id, max_vel, radius, init_pose (x, y,
    z, h), goal_radius, cyclic_goals, goals [(x, y, h)]}]; AssertionError naming the parameter otherwise."""
    doc = yaml.safe_load(text)
    assert isinstance(doc, dict) and list(doc) == ["hunav_loader"], "the file sets the node hunav_loader's parameters"
    node = doc["hunav_loader"]
    assert isinstance(node, dict) and list(node) == ["ros__parameters"], "hunav_loader: only ros__parameters"
    params = node["ros__parameters"]
    out = {"map": _typed(params.get("map"), str, "map"),
           "publish_people": _typed(params.get("publish_people"), bool, "publish_people"), "agents": []}
    ids = set()
    for name in _names(params.get("agents"), "agents"):
        agent = params.get(name)
        assert isinstance(agent, dict), f"agent {name} has no parameters"
        got = {key: _typed(agent.get(key), kind, f"{name}.{key}") for key, kind in _AGENT.items()}
        pose = agent.get("init_pose")
        assert isinstance(pose, dict), f"{name}.init_pose is missing"
        got["init_pose"] = tuple(_typed(pose.get(k), float, f"{name}.init_pose.{k}") for k in "xyzh")
        goals = []
        for goal in _names(agent.get("goals"), f"{name}.goals"):
            g = agent.get(goal)
            assert isinstance(g, dict), f"goal {name}.{goal} has no x, y, h"
            goals.append(tuple(_typed(g.get(k), float, f"{name}.{goal}.{k}") for k in "xyh"))
        assert got["id"] not in ids, f"{name}.id {got['id']} is another agent's"
        ids.add(got["id"])
        assert got["behavior"] in HUNAV_BEHAVIORS.values(), f"{name}.behavior {got['behavior']} is none of 1-6"
        assert 0 <= got["skin"] <= 4, f"{name}.skin {got['skin']} is outside 0-4"
        assert got["radius"] > 0 and got["goal_radius"] > 0 and got["max_vel"] >= 0, f"{name}: a size out of range"
        out["agents"].append({"name": name, **got, "goals": goals})
    return out
