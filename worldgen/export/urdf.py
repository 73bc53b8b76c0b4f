"""URDF exporter: Scene -> lxml tree, filled into ``templates/world.urdf``.

URDF describes one kinematic tree, so a world becomes one "robot":

- The root link is ``world`` (in the skeleton). MuJoCo's importer maps a link
  of that name onto its world body and Gazebo welds it to the world, so the
  root carries no inertia that a simulator could reject.
- Every node is a link of the same name, with an ``<inertial>`` from the
  node's mass and inertia (valid for every shape), a ``<visual>`` with its
  material, and a ``<collision>`` named after the node unless the node has no
  collision (markers). MuJoCo names its geom after the collision.
- A root node hangs from ``world`` on a joint named after the node: ``fixed``
  when static, ``floating`` when dynamic (MuJoCo imports that as a free joint,
  so a dynamic body moves as in the MJCF; check_urdf accepts it), or on its
  scene Joint when one names it (``parent="world"``).
- A child node hangs from its parent's link on the scene Joint naming it
  (``revolute`` with ``<limit lower upper effort velocity>`` and
  ``<dynamics damping>``), or on a ``fixed`` joint named after the node.
- URDF puts a child link's frame on its joint, so for a revolute child the
  link frame is the scene Joint's frame and the shapes are offset back by the
  inverse of ``joint.pose``.
- Initial angle: URDF has no place for it. ``node.pose`` is the pose at
  ``joint.initial`` (a door ajar) and is written as it is, so the URDF shows
  the same geometry as the SDF, the MJCF and world.json; the joint's zero is
  therefore the initial angle, and the limits are shifted to keep the same
  physical range: ``lower = lo - initial``, ``upper = hi - initial`` (the SDF
  exporter does the same). The joint position a URDF simulator reports is
  ``angle - initial``; world.json's ``doors[].angle`` holds ``initial``.
- Friction is not part of URDF. Each colliding link gets
  ``<gazebo reference=...><mu1/><mu2/></gazebo>`` (Gazebo's URDF extension,
  read when Gazebo converts the URDF; check_urdf and MuJoCo ignore it).
- Meshes refer to ``shape.uri`` (relative to the world folder, written by
  :mod:`worldgen.export.meshes`) with ``scale``.
- A ``<mujoco>`` element in the skeleton keeps MuJoCo from fusing the fixed
  links into one body and from stripping ``meshes/`` off mesh paths; its
  ``<option timestep gravity>`` carries the world's physics step and gravity
  (MuJoCo reads it; URDF itself has no world physics). The real-time factor has
  no place in URDF, nor does friction for MuJoCo's importer (it reads only
  ``compiler``/``option``/``size`` there), so a URDF loaded in MuJoCo keeps its
  default friction; Gazebo reads the ``<gazebo>`` mu1/mu2 above.
- Movers (``scene.movers``) cannot be expressed in URDF and are left out;
  world.json's ``dynamic_obstacles[].formats.urdf`` is null to say so.
"""

from __future__ import annotations

import numpy as np
from lxml import etree

from worldgen.errors import SceneError
from worldgen.export.mjcf import RESERVED_NAME, joints_by_child, mass_properties
from worldgen.export.xml import load_template, sub
from worldgen.floats import fmt, fmt_seq
from worldgen.scene import Box, Cylinder, Joint, Mesh, Node, Scene, Sphere, matrix_to_pose

__all__ = ["to_urdf", "TEMPLATE", "link_offset", "joint_origin"]

TEMPLATE = "world.urdf"


def link_offset(joint: Joint | None) -> np.ndarray:
    """(4, 4) pose of a node's URDF link frame in the node's frame.

    A revolute joint's frame (``joint.pose``, in the child's frame) becomes the
    link frame; elsewhere the link frame is the node frame.
    """
    if joint is not None and joint.kind == "revolute":
        return joint.pose.matrix()
    return np.eye(4)


def joint_origin(node: Node, joint: Joint | None, parent_joint: Joint | None) -> np.ndarray:
    """(4, 4) URDF joint origin: the node's link frame in its parent's link frame (at the initial angle)."""
    return np.linalg.inv(link_offset(parent_joint)) @ node.pose.matrix() @ link_offset(joint)


def to_urdf(scene: Scene, name: str = "world"):
    """The scene as a URDF document (an lxml ElementTree)."""
    joints = joints_by_child(scene)
    _check_joint_names(scene, joints)
    tree = load_template(TEMPLATE)
    robot = tree.getroot()
    robot.set("name", name)
    # Only MuJoCo's importer reads physics from a URDF: step and gravity go in its extension.
    sub(robot.find("mujoco"), "option", timestep=fmt(scene.physics.step_size), gravity=fmt_seq(scene.physics.gravity))
    materials = _write_materials(robot, scene)
    for node in scene.nodes:
        joint = joints.get(node.name)
        parent_joint = joints.get(node.parent) if node.parent is not None else None
        _write_link(robot, node, joint, materials)
        _write_joint(robot, node, joint, parent_joint)
        if node.shape is not None and node.collision:
            gz = sub(robot, "gazebo", reference=node.name)
            sub(gz, "mu1", fmt(node.material.friction))
            sub(gz, "mu2", fmt(node.material.friction))
    return tree


def _joint_name(node: Node, joint: Joint | None) -> str:
    return joint.name if joint is not None else node.name


def _check_joint_names(scene: Scene, joints: dict[str, Joint]) -> None:
    seen: dict[str, str] = {}
    for node in scene.nodes:
        jname = _joint_name(node, joints.get(node.name))
        if jname in seen:
            raise SceneError(f"URDF joint name {jname!r} would attach both {seen[jname]!r} and {node.name!r}; "
                             "rename the scene joint")
        seen[jname] = node.name


def _write_materials(robot, scene: Scene) -> dict[str, str]:
    """Top-level ``<material>`` elements; returns {node name: material name}.

    Materials are shared by name; a name reused with another colour gets a suffix,
    because URDF keeps one colour per material name.
    """
    by_key: dict[tuple, str] = {}
    used: set[str] = set()
    result: dict[str, str] = {}
    at = _first_link_index(robot) + 1  # after the root link, before any link that uses them
    for node in scene.nodes:
        if node.shape is None:
            continue
        key = (node.material.name, node.material.rgba)
        if key not in by_key:
            mname, k = node.material.name, 1
            while mname in used:
                mname, k = f"{node.material.name}_{k}", k + 1
            used.add(mname)
            by_key[key] = mname
            mat = etree.Element("material", name=mname)
            sub(mat, "color", rgba=fmt_seq(node.material.rgba))
            robot.insert(at, mat)
            at += 1
        result[node.name] = by_key[key]
    return result


def _first_link_index(robot) -> int:
    for i, child in enumerate(robot):
        if child.tag == "link":
            return i
    return len(robot)


#: The identity origin, by far the most common one: written without any matrix work.
_IDENTITY = {"xyz": "0 0 0", "rpy": "0 0 0"}


def _pose_attrs(pose) -> dict[str, str]:
    return {"xyz": fmt_seq((pose.x, pose.y, pose.z)), "rpy": fmt_seq((pose.roll, pose.pitch, pose.yaw))}


def _matrix_attrs(m: np.ndarray) -> dict[str, str]:
    return _pose_attrs(matrix_to_pose(m))


def _write_link(robot, node: Node, joint: Joint | None, materials) -> None:
    link = sub(robot, "link", name=node.name)
    offset = link_offset(joint) if joint is not None and joint.kind == "revolute" else None
    back = _IDENTITY if offset is None else _matrix_attrs(np.linalg.inv(offset))  # node frame in link frame
    inertial = sub(link, "inertial")
    sub(inertial, "origin", **back)
    mass, (ixx, iyy, izz) = mass_properties(node)
    sub(inertial, "mass", value=mass)
    sub(inertial, "inertia", ixx=ixx, ixy="0", ixz="0", iyy=iyy, iyz="0", izz=izz)
    if node.shape is None:
        return
    kind, attrs = _geometry_attrs(node)
    visual = sub(link, "visual", name=node.name)
    sub(visual, "origin", **back)
    sub(sub(visual, "geometry"), kind, **attrs)
    sub(visual, "material", name=materials[node.name])
    if node.collision:
        collision = sub(link, "collision", name=node.name)
        sub(collision, "origin", **back)
        sub(sub(collision, "geometry"), kind, **attrs)


def _geometry_attrs(node: Node) -> tuple[str, dict[str, str]]:
    """(element name, attributes) of the node's shape inside ``<geometry>``."""
    shape = node.shape
    if isinstance(shape, Box):
        return "box", {"size": fmt_seq(shape.size)}
    if isinstance(shape, Cylinder):
        return "cylinder", {"radius": fmt(shape.radius), "length": fmt(shape.length)}
    if isinstance(shape, Sphere):
        return "sphere", {"radius": fmt(shape.radius)}
    if isinstance(shape, Mesh):
        return "mesh", {"filename": shape.uri, "scale": fmt_seq(shape.scale)}
    raise TypeError(f"node {node.name!r}: unknown shape {shape!r}")


def _write_joint(robot, node: Node, joint: Joint | None, parent_joint: Joint | None) -> None:
    if joint is not None and joint.kind == "revolute":
        kind = "revolute"
    elif node.parent is None and not node.static and joint is None:
        kind = "floating"
    else:
        kind = "fixed"
    el = sub(robot, "joint", name=_joint_name(node, joint), type=kind)
    sub(el, "parent", link=node.parent or RESERVED_NAME)
    sub(el, "child", link=node.name)
    if kind != "revolute" and (parent_joint is None or parent_joint.kind != "revolute"):
        origin = _pose_attrs(node.pose)  # link frames are node frames here: the pose as the scene has it
    else:
        origin = _matrix_attrs(joint_origin(node, joint, parent_joint))
    sub(el, "origin", **origin)
    if kind == "revolute":
        sub(el, "axis", xyz=fmt_seq(joint.axis))
        lo, hi = joint.limits
        # The written pose is the joint's zero: measure the limits from the initial angle.
        sub(el, "limit", lower=fmt(lo - joint.initial), upper=fmt(hi - joint.initial),
            effort=fmt(joint.effort), velocity=fmt(joint.velocity))
        sub(el, "dynamics", damping=fmt(joint.damping))
