"""``robot.urdf``: the robot of :mod:`worldgen.export.robot` (robot.sdf) as one URDF tree (links, joints, inertias,
geometry) for robot_state_publisher and RViz; Gazebo spawns the SDF. The same numbers as the SDF, from the
world's robot description; bytes-stable."""

from __future__ import annotations

import math

from lxml import etree

from worldgen.export.robot_body import COLOUR, DEFAULT_NAME, chassis, described, dimensions, inertia_cylinder, parts
from worldgen.export.xml import sub, to_bytes
from worldgen.floats import fmt, fmt_seq

__all__ = ["robot_urdf"]


def _urdf_link(robot, name: str, shape=None, mass: float = 0.0, diag=(0, 0, 0), origin=(0, 0, 0, 0, 0, 0)) -> None:
    link = sub(robot, "link", name=name)
    if shape is None:
        return
    inertial = sub(link, "inertial")
    sub(inertial, "origin", xyz=fmt_seq(origin[:3]), rpy=fmt_seq(origin[3:]))
    sub(inertial, "mass", value=fmt(mass))
    sub(inertial, "inertia", ixx=fmt(diag[0]), ixy="0", ixz="0", iyy=fmt(diag[1]), iyz="0", izz=fmt(diag[2]))
    for kind in ("visual", "collision"):
        el = sub(link, kind)
        sub(el, "origin", xyz=fmt_seq(origin[:3]), rpy=fmt_seq(origin[3:]))
        geometry = sub(el, "geometry")
        if shape[0] == "cylinder":
            sub(geometry, "cylinder", radius=fmt(shape[1]), length=fmt(shape[2]))
        else:
            sub(geometry, "sphere", radius=fmt(shape[1]))
        if kind == "visual":
            sub(sub(el, "material", name="robot_orange"), "color", rgba=COLOUR)


def _urdf_joint(robot, name: str, kind: str, parent: str, child: str, xyz, rpy=(0, 0, 0), axis=None) -> None:
    joint = sub(robot, "joint", name=name, type=kind)
    sub(joint, "parent", link=parent)
    sub(joint, "child", link=child)
    sub(joint, "origin", xyz=fmt_seq(xyz), rpy=fmt_seq(rpy))
    if axis is not None:
        sub(joint, "axis", xyz=axis)


def robot_urdf(world, *, name: str = DEFAULT_NAME) -> str:
    """``robot.urdf`` of the robot for ``world``: the SDF's links and joints, for robot_state_publisher."""
    robot_description = described(world)
    mass = robot_description.mass
    d = dimensions(robot_description)
    length, zc = chassis(d)
    robot = etree.Element("robot", name=name)
    _urdf_link(robot, "base_footprint")
    _urdf_link(robot, "base_link", ("cylinder", d.radius, length), mass,
               inertia_cylinder(mass, d.radius, length), (0, 0, zc, 0, 0, 0))
    _urdf_joint(robot, "base_footprint_joint", "fixed", "base_footprint", "base_link", (0, 0, d.wheel_radius))
    for part, kind, xyz, shape, mass, _ in parts(d):
        if shape[0] == "cylinder":
            _urdf_link(robot, part, shape, mass, inertia_cylinder(mass, shape[1], shape[2]))
            _urdf_joint(robot, f"{part}_joint", "continuous", "base_link", part, xyz, (-math.pi / 2, 0, 0), "0 0 1")
        else:
            _urdf_link(robot, part, shape, mass, (0.4 * mass * shape[1] ** 2,) * 3)
            _urdf_joint(robot, f"{part}_joint", "fixed", "base_link", part, xyz)
    for part, z in (("base_scan", d.lidar_height - d.wheel_radius), ("imu_link", zc)):
        _urdf_link(robot, part)  # a frame only: no body of its own
        _urdf_joint(robot, f"{part}_joint", "fixed", "base_link", part, (0, 0, z))
    return to_bytes(robot).decode()
