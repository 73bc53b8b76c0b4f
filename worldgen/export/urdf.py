"""URDF exporter: Scene -> URDF bytes, filled into ``templates/world.urdf``.

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

from worldgen.errors import SceneError
from worldgen.export.bodies import RESERVED_NAME, joints_by_child, mass_properties
from worldgen.export.xml import XmlText, escape_attr, fill, load_template, sub
from worldgen.files import URDF_NAME
from worldgen.floats import fmt, fmt_seq
from worldgen.scene import Box, Cylinder, Joint, Mesh, Node, Scene, Sphere, matrix_to_pose
from worldgen.scene.ground import ground_scene

__all__ = ["to_urdf", "TEMPLATE", "link_offset", "joint_origin"]

TEMPLATE = URDF_NAME  # worldgen/templates names each skeleton after the file it becomes


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


def to_urdf(scene: Scene, name: str = "world") -> bytes:
    """The scene as a URDF document: UTF-8 bytes, pretty-printed (see the module docstring).

    The skeleton is filled with lxml; the materials, links, joints and
    ``<gazebo>`` blocks are written as text (:class:`~worldgen.export.xml.XmlText`).
    """
    scene = ground_scene(scene)  # the terrain as one mesh; the scene itself on flat ground
    joints = joints_by_child(scene)
    _check_joint_names(scene, joints)
    tree = load_template(TEMPLATE)
    robot = tree.getroot()
    robot.set("name", name)
    # Only MuJoCo's importer reads physics from a URDF: step and gravity go in its extension.
    sub(robot.find("mujoco"), "option", timestep=fmt(scene.physics.step_size), gravity=fmt_seq(scene.physics.gravity))
    out = XmlText(depth=1)
    materials = _write_materials(out, scene)
    for node in scene.nodes:
        joint = joints.get(node.name)
        parent_joint = joints.get(node.parent) if node.parent is not None else None
        _write_link(out, node, joint, materials)
        _write_joint(out, node, joint, parent_joint)
        if node.shape is not None and node.collision:
            mu = fmt(node.material.friction)
            out.open("gazebo", f' reference="{node.name}"')
            out.leaf("mu1", mu)
            out.leaf("mu2", mu)
            out.close("gazebo")
    return fill(tree, robot, out)


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


def _write_materials(out: XmlText, scene: Scene) -> dict[str, str]:
    """Top-level ``<material>`` elements, before any link that uses them; returns {node name: material name}.

    Materials are shared by name; a name reused with another colour gets a suffix,
    because URDF keeps one colour per material name.
    """
    by_key: dict[tuple, str] = {}
    used: set[str] = set()
    result: dict[str, str] = {}
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
            out.open("material", f' name="{escape_attr(mname)}"')
            out.empty("color", f' rgba="{fmt_seq(node.material.rgba)}"')
            out.close("material")
        result[node.name] = by_key[key]
    return result


#: The identity origin, by far the most common one: written without any matrix work.
_IDENTITY = ' xyz="0 0 0" rpy="0 0 0"'


def _pose_attrs(pose) -> str:
    return f' xyz="{fmt_seq((pose.x, pose.y, pose.z))}" rpy="{fmt_seq((pose.roll, pose.pitch, pose.yaw))}"'


def _matrix_attrs(m: np.ndarray) -> str:
    return _pose_attrs(matrix_to_pose(m))


def _write_link(out: XmlText, node: Node, joint: Joint | None, materials) -> None:
    out.open("link", f' name="{node.name}"')
    offset = link_offset(joint) if joint is not None and joint.kind == "revolute" else None
    back = _IDENTITY if offset is None else _matrix_attrs(np.linalg.inv(offset))  # node frame in link frame
    mass, (ixx, iyy, izz) = mass_properties(node)
    out.open("inertial")
    out.empty("origin", back)
    out.empty("mass", f' value="{mass}"')
    out.empty("inertia", f' ixx="{ixx}" ixy="0" ixz="0" iyy="{iyy}" iyz="0" izz="{izz}"')
    out.close("inertial")
    if node.shape is not None:
        geometry = _geometry(node)
        out.open("visual", f' name="{node.name}"')
        out.empty("origin", back)
        out.open("geometry")
        out.empty(*geometry)
        out.close("geometry")
        out.empty("material", f' name="{escape_attr(materials[node.name])}"')
        out.close("visual")
        if node.collision:
            out.open("collision", f' name="{node.name}"')
            out.empty("origin", back)
            out.open("geometry")
            out.empty(*geometry)
            out.close("geometry")
            out.close("collision")
    out.close("link")


def _geometry(node: Node) -> tuple[str, str]:
    """(element name, attributes) of the node's shape inside ``<geometry>``."""
    shape = node.shape
    if isinstance(shape, Box):
        return "box", f' size="{fmt_seq(shape.size)}"'
    if isinstance(shape, Cylinder):
        return "cylinder", f' radius="{fmt(shape.radius)}" length="{fmt(shape.length)}"'
    if isinstance(shape, Sphere):
        return "sphere", f' radius="{fmt(shape.radius)}"'
    if isinstance(shape, Mesh):
        return "mesh", f' filename="{escape_attr(shape.uri)}" scale="{fmt_seq(shape.scale)}"'
    raise SceneError(f"node {node.name!r}: unknown shape {shape!r}")


def _write_joint(out: XmlText, node: Node, joint: Joint | None, parent_joint: Joint | None) -> None:
    if joint is not None and joint.kind == "revolute":
        kind = "revolute"
    elif node.parent is None and not node.static and joint is None:
        kind = "floating"
    else:
        kind = "fixed"
    out.open("joint", f' name="{_joint_name(node, joint)}" type="{kind}"')
    out.empty("parent", f' link="{node.parent or RESERVED_NAME}"')
    out.empty("child", f' link="{node.name}"')
    if kind != "revolute" and (parent_joint is None or parent_joint.kind != "revolute"):
        origin = _pose_attrs(node.pose)  # link frames are node frames here: the pose as the scene has it
    else:
        origin = _matrix_attrs(joint_origin(node, joint, parent_joint))
    out.empty("origin", origin)
    if kind == "revolute" and joint is not None:  # revolute: a joint of that kind
        out.empty("axis", f' xyz="{fmt_seq(joint.axis)}"')
        lo, hi = joint.limits
        # The written pose is the joint's zero: measure the limits from the initial angle.
        out.empty("limit", f' lower="{fmt(lo - joint.initial)}" upper="{fmt(hi - joint.initial)}" '
                           f'effort="{fmt(joint.effort)}" velocity="{fmt(joint.velocity)}"')
        out.empty("dynamics", f' damping="{fmt(joint.damping)}"')
    out.close("joint")
