"""Re-checks of a generated world by independent means: geometry, the reference consumers, MuJoCo's rays."""

from __future__ import annotations

import math

import mujoco
import numpy as np
from lxml import etree

from support.reftools_mujoco import load_and_step
from support.reftools_sdf import check_sdf
from support.reftools_urdf import check_urdf
from worldgen.export.xml import safe_parser

__all__ = ["footprint_distance", "recheck", "reference_tools", "ray", "with_probe"]


def footprint_distance(node, xy: np.ndarray) -> np.ndarray:
    """(n,) distance from points to a root node's floor shadow: upright cylinder or yawed box."""
    assert node.parent is None and node.pose.roll == 0 and node.pose.pitch == 0
    d = xy - [node.pose.x, node.pose.y]
    if node.shape.kind == "cylinder":
        return np.hypot(d[:, 0], d[:, 1]) - node.shape.radius
    assert node.shape.kind == "box"
    c, s = math.cos(node.pose.yaw), math.sin(node.pose.yaw)
    lx, ly = c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]
    hx, hy = node.shape.size[0] / 2, node.shape.size[1] / 2
    return np.hypot(np.maximum(np.abs(lx) - hx, 0), np.maximum(np.abs(ly) - hy, 0))


def recheck(world) -> None:
    """Spawn, goal and the whole reference path (sampled at radius / 8) keep the footprint plus
    clearance off every collider and inside the bounds."""
    robot, scene = world.robot, world.scene
    colliders = [n for n in scene.nodes if n.collision and n.shape is not None and n.role != "floor"]
    (x0, y0), (x1, y1) = scene.bounds
    assert world.feasibility.feasible, [c.detail for c in world.feasibility.failed()]
    for task, path in zip(world.tasks, world.feasibility.paths):
        wp = path.waypoints
        assert np.allclose(wp[0], [task.spawn.x, task.spawn.y]) and np.allclose(wp[-1], [task.goal.x, task.goal.y])
        pts = [wp[:1]]
        for a, b in zip(wp[:-1], wp[1:]):
            n = max(1, math.ceil(np.hypot(*(b - a)) / (robot.radius / 8)))
            pts.append(a + np.linspace(0, 1, n + 1)[1:, None] * (b - a))
        pts = np.vstack(pts)
        nearest = np.min([footprint_distance(n, pts) for n in colliders], axis=0) if colliders else np.inf
        assert np.all(nearest >= robot.inflation - 1e-6), float(np.min(nearest))
        assert np.all((pts[:, 0] - robot.inflation >= x0 - 1e-6) & (pts[:, 0] + robot.inflation <= x1 + 1e-6))
        assert np.all((pts[:, 1] - robot.inflation >= y0 - 1e-6) & (pts[:, 1] + robot.inflation <= y1 + 1e-6))
        # path.length is the exact taut length (arcs included); the written polyline goes round
        # each arc on a circumscribed polygon, a little longer, never shorter.
        length = float(np.hypot(*np.diff(wp, axis=0).T).sum())
        assert path.length - 1e-6 <= length <= path.length * 1.005 + 1e-6
        assert path.length >= math.hypot(task.goal.x - task.spawn.x, task.goal.y - task.spawn.y) - 1e-9


def reference_tools(world, folder) -> None:
    """libsdformat strict, check_urdf, and MuJoCo (load + 500 steps, no warning) on the written files."""
    out = world.write(folder)
    ok, messages = check_sdf(out / "world.sdf")
    assert ok, messages
    check_urdf(out / "world.urdf")
    model, _ = load_and_step(out / "world.mjcf.xml")
    names = {model.geom(i).name for i in range(model.ngeom)}
    assert {n.name for n in world.scene.nodes if n.shape is not None} <= names


def ray(world, origin_xy, direction, z):
    """(distance, geom name) of MuJoCo's mj_ray on the world's MJCF from (x, y, z) along ``direction`` (rad)."""
    model = mujoco.MjModel.from_xml_string(world.to_mjcf())
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    geom = np.zeros(1, dtype=np.int32)
    d = mujoco.mj_ray(model, data, np.array([origin_xy[0], origin_xy[1], z]),
                      np.array([math.cos(direction), math.sin(direction), 0.0]), None, True, -1, geom)
    return d, (model.geom(int(geom[0])).name if geom[0] >= 0 else None)


def with_probe(mjcf: str, radius: float, height: float) -> str:
    """The MJCF with a collision-free mocap cylinder ``probe`` (radius, height) added to its worldbody."""
    root = etree.fromstring(mjcf.encode(), safe_parser())
    body = etree.SubElement(root.find("worldbody"), "body", name="probe", mocap="true", pos=f"0 0 {height / 2}")
    etree.SubElement(body, "geom", name="probe", type="cylinder", size=f"{radius} {height / 2}",
                     contype="0", conaffinity="0")
    return etree.tostring(root).decode()
