"""Doors in a scene: which joints are doors, where their leaves are at any angle, and world.json's ``doors[]``.

Conventions (the ``door`` generator follows them; a hand-built scene may too):

- A *door* is a revolute :class:`~worldgen.scene.Joint` whose child node has
  role ``door`` (the leaf). Angle 0 is closed; the joint's axis is oriented so
  that opening is towards the limit of larger magnitude (the *open limit*).
- The leaf's parent, when it is a ``door_frame`` box, is the frame's *head*
  (lintel): it spans the doorway exactly, centred on it, its local x across the
  opening and its local +y pointing to the side the leaf opens into. That gives
  ``passage`` without guessing; any other parent gives ``passage: null``.
- The door's ``width`` is the doorway's width (the head's size x); the leaf
  itself is a little narrower, so it never rubs the frame.

Feasibility plans the reference path with every leaf at its open limit
(:func:`open_scene`) and reports separately whether the goal is reachable with
the doors as they start (:func:`fixed_scene`). A task needs a door opened where
the robot's footprint, swept along that path, meets a leaf as it starts, closed
or ajar (:func:`leaves_in_the_way`).
"""

from __future__ import annotations

import math
from typing import Mapping, Optional

import numpy as np
import shapely

from worldgen.scene.footprint import scene_footprints
from worldgen.scene.graph import Joint, Node, Scene
from worldgen.scene.pose import matrix_to_pose
from worldgen.scene.shapes import Box

__all__ = ["swept_scenes", "door_joints", "open_angle", "state_of", "scene_at", "open_scene", "fixed_scene", "door_records",
           "leaves_in_the_way", "requires_door_open", "STATE_TOL"]

#: Angles (rad) closer than this to 0 or to the open limit count as closed or open.
STATE_TOL = 1e-6


def door_joints(scene: Scene) -> list[Joint]:
    """The revolute joints whose child is a door leaf, in the scene's joint order."""
    out = []
    for joint in scene.joints:
        if joint.kind != "revolute" or joint.child == "world":
            continue
        if scene.node(joint.child).role == "door":
            out.append(joint)
    return out


def open_angle(joint: Joint) -> float:
    """The limit of larger magnitude (angle 0 being closed); the upper one on a tie."""
    lo, hi = joint.limits
    return lo if abs(lo) > abs(hi) else hi


def state_of(joint: Joint) -> str:
    """``closed`` at angle 0, ``open`` at the open limit, ``ajar`` between."""
    if abs(joint.initial) <= STATE_TOL:
        return "closed"
    if abs(joint.initial - open_angle(joint)) <= STATE_TOL:
        return "open"
    return "ajar"


def _axis_rotation(axis, angle: float) -> np.ndarray:
    """(4, 4) rotation by ``angle`` about the unit ``axis`` through the origin (Rodrigues)."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    m = np.eye(4)
    m[:3, :3] = np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * (k @ k)
    return m


def _child_pose_at(node: Node, joint: Joint, angle: float):
    """The child's pose (in its parent) with the joint at ``angle`` instead of ``joint.initial``.

    The hinge frame stays put in the parent; the child turns about it:
    P(angle) = P(initial) J R(angle - initial) J^-1, J = the joint frame in the child.
    """
    j = joint.pose.matrix()
    m = node.pose.matrix() @ j @ _axis_rotation(joint.axis, angle - joint.initial) @ np.linalg.inv(j)
    return matrix_to_pose(m)


def scene_at(scene: Scene, angles: Mapping[str, float]) -> Scene:
    """``scene`` with the named revolute joints at the given angles (descendants follow)."""
    if not angles:
        return scene
    by_child = {j.child: j for j in scene.joints if j.name in angles}
    nodes = []
    for node in scene.nodes:
        joint = by_child.get(node.name)
        if joint is not None and abs(angles[joint.name] - joint.initial) > 0:
            node = Node(node.name, node.role, node.shape, _child_pose_at(node, joint, angles[joint.name]),
                        node.parent, node.static, node.mass, node.material, node.collision)
        nodes.append(node)
    return scene.with_nodes(nodes)


def open_scene(scene: Scene) -> Scene:
    """``scene`` with every door leaf at its open limit (the scene itself when none has to move)."""
    angles = {j.name: open_angle(j) for j in door_joints(scene) if j.initial != open_angle(j)}
    return scene_at(scene, angles)


def swept_scenes(scene: Scene, spacing: float) -> list[Scene]:
    """``scene`` with every door leaf at angles from its initial angle to its open limit (both ends
    included), no two of them more than ``spacing`` m apart at the leaf's far edge: whatever keeps that much
    from each of them keeps clear of the whole sweep. [] when no leaf has to move."""
    joints = [j for j in door_joints(scene) if j.initial != open_angle(j)]
    if not joints:
        return []
    children = {node.name: node for node in scene.nodes}
    steps = max(math.ceil(abs(open_angle(j) - j.initial) * _leaf_width(children[j.child]) / spacing) for j in joints)
    return [scene_at(scene, {j.name: j.initial + (open_angle(j) - j.initial) * k / steps for j in joints})
            for k in range(steps + 1)]


def _passage(scene: Scene, joint: Joint) -> Optional[dict]:
    head = scene.node(joint.parent) if joint.parent != "world" else None
    if head is None or head.role != "door_frame" or not isinstance(head.shape, Box):
        return None
    m = scene.world_matrix(head.name)
    normal = m[:2, 1] / max(np.hypot(*m[:2, 1]), 1e-300)
    return {"center": [float(m[0, 3]), float(m[1, 3])], "width": float(head.shape.size[0]),
            "normal": [float(normal[0]), float(normal[1])]}


def door_records(scene: Scene) -> list[dict]:
    """world.json's ``doors[]``: one record per door joint (docs/world-json.md's fields, plus ``joint``).

    ``hinge`` is where the hinge axis meets the floor (z = 0), ``axis`` the unit
    axis in the world frame (positive angles open the door), ``angle`` the
    initial joint angle.
    """
    out = []
    for joint in door_joints(scene):
        leaf = scene.node(joint.child)
        frame = scene.world_matrix(leaf.name) @ joint.pose.matrix()
        axis = frame[:3, :3] @ np.asarray(joint.axis, dtype=float)
        axis = axis / np.linalg.norm(axis)
        origin = frame[:3, 3]
        # Slide along the axis to the floor, where the axis is not horizontal.
        hinge = origin - axis * (origin[2] / axis[2]) if abs(axis[2]) > 1e-9 else origin
        passage = _passage(scene, joint)
        width = passage["width"] if passage else float(_leaf_width(leaf))
        out.append({
            "name": leaf.name,
            "joint": joint.name,
            "hinge": [float(v) for v in hinge],
            "axis": [float(v) for v in axis],
            "width": width,
            "state": state_of(joint),
            "angle": float(joint.initial),
            "limits": [float(joint.limits[0]), float(joint.limits[1])],
            "damping": float(joint.damping),
            "passage": passage,
        })
    return out


def _leaf_width(leaf: Node) -> float:
    if isinstance(leaf.shape, Box):
        return leaf.shape.size[0]
    assert leaf.shape is not None, "a door's leaf has a shape"
    lo, hi = leaf.shape.local_corners().min(axis=0), leaf.shape.local_corners().max(axis=0)
    return float(max(hi[0] - lo[0], hi[1] - lo[1]))


def fixed_scene(scene: Scene) -> Scene:
    """``scene`` with every door leaf held where it starts: door hinges become fixed joints.

    Feasibility plans through doors at their open limit; on this scene the same
    check answers whether a task can be driven without moving any leaf.
    """
    doors = {j.name for j in door_joints(scene)}
    if not doors:
        return scene
    joints = tuple(Joint(j.name, "fixed", j.parent, j.child, j.pose) if j.name in doors else j for j in scene.joints)
    return Scene(scene.nodes, joints, scene.bounds, scene.physics, scene.movers, scene.terrain)


def leaves_in_the_way(scene: Scene, waypoints, radius: float, height: float) -> list[str]:
    """Door leaves (names, in joint order) that a disc of ``radius`` swept along ``waypoints`` meets.

    Each leaf stands at its initial angle, closed or ajar; only the part of it
    below ``height`` (the robot's top) counts, as its floor shadow. The sweep is
    exact: the polyline buffered by ``radius``, so "meets" is a distance below
    ``radius`` between the leaf's shadow and the path.
    """
    if waypoints is None:
        return []
    leaves = [j.child for j in door_joints(scene)]
    if not leaves:
        return []
    w = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    path = shapely.LineString(w) if len(w) > 1 else shapely.Point(w[0])
    prints = {fp.name: fp for fp in scene_footprints(scene, height) if fp.name in leaves}
    out = []
    for name in leaves:
        fp = prints.get(name)
        if fp is None:  # a leaf entirely above the robot
            continue
        shadow = fp.polygon if fp.polygon is not None else shapely.Point(fp.centre).buffer(fp.radius, quad_segs=64)
        if shadow.distance(path) < radius:
            out.append(name)
    return out


def requires_door_open(scene: Scene, waypoints, robot) -> bool:
    """True when ``robot``'s footprint, swept along ``waypoints``, meets any door leaf as it starts."""
    return bool(leaves_in_the_way(scene, waypoints, robot.radius, robot.height))
