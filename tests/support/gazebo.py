"""Gazebo as a reference tool: finding it (skip on a laptop, fail on CI) and comparing what it reports
with world.json.

Gazebo publishes a model's pose in the world frame and a link's in its model's frame; world.json gives
every entity's world pose. A door leaf is a link of its head's model, so its world pose is the head's pose
composed with the leaf link's.
"""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

from support import missing_tool

__all__ = ["gazebo_install", "install_cache", "every_case", "release_cases", "lidar_robot_sdf", "scan_ranges", "scan_stamp", "fit_circle", "seen_centres",
           "quat_from_rpy", "compose", "world_poses", "pose_errors", "POSITION_TOL", "ANGLE_TOL"]

#: How close Gazebo's poses must be to world.json: 1 mm, and 1 mrad (Gazebo prints 6 significant digits).
POSITION_TOL = 1e-3
ANGLE_TOL = 1e-3


def gazebo_install(release: str | None = None):
    """The Gazebo install the tests use (worldgen.sim.gazebo.locate; ``release`` one of the contract's
    SIM_GZ_RELEASES, None for the default install), or skip (laptop) / fail (CI: every release must be there)."""
    from worldgen.sim.gazebo import GazeboMissingError, locate

    try:
        return locate(release=release)
    except GazeboMissingError as exc:
        missing_tool(f"Gazebo {release or ''} ({exc})")


def install_cache():
    """``get(release)``: :func:`gazebo_install` of that release, located once per cache (a module's fixture)."""
    found: dict = {}

    def get(release: str):
        if release not in found:
            found[release] = gazebo_install(release)
        return found[release]

    return get


def every_case() -> bool:
    """Whether the later releases run every case, not only their sample (``WORLDGEN_GAZEBO_ALL=1``): the suite
    runs each world in the default release and a sample per generator in the others, to stay in its budget."""
    return os.environ.get("WORLDGEN_GAZEBO_ALL") == "1"


def release_cases(cases: list[str], sample: set[str], first: set[str] | None = None) -> list:
    """``(release, case)`` parameters: every case in the default release (or only those of ``first``); in the
    others the ``sample`` cases; the rest too when :func:`every_case` says so (else they are left out of the
    run, not skipped)."""
    from worldgen.export.contract import SIM_GZ_RELEASES

    default, *others = SIM_GZ_RELEASES
    out = [pytest.param(default, c, id=f"{default}-{c}") for c in cases if first is None or c in first or every_case()]
    for rel in others:
        out += [pytest.param(rel, c, id=f"{rel}-{c}") for c in cases if c in sample or every_case()]
    return out


def quat_from_rpy(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """(x, y, z, w) of R = Rz(yaw) Ry(pitch) Rx(roll), SDF's convention."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return np.array([sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
                     cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy])


def _qmul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return np.array([aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz])


def _rotate(q, v):
    qv = np.array([v[0], v[1], v[2], 0.0])
    conj = np.array([-q[0], -q[1], -q[2], q[3]])
    return _qmul(_qmul(q, qv), conj)[:3]


def compose(parent, child) -> tuple[float, ...]:
    """parent * child for (x, y, z, qx, qy, qz, qw) poses."""
    p, c = np.asarray(parent, float), np.asarray(child, float)
    xyz = p[:3] + _rotate(p[3:], c[:3])
    return tuple(xyz) + tuple(_qmul(p[3:], c[3:]))


def world_poses(gazebo_poses: dict[str, tuple[float, ...]]) -> dict[str, tuple[float, ...]]:
    """Every model's and link's world pose, keyed by its own (unscoped) name, from GazeboServer.poses()."""
    out: dict[str, tuple[float, ...]] = {}
    for scoped, pose in sorted(gazebo_poses.items(), key=lambda kv: kv[0].count("::")):
        parent, _, name = scoped.rpartition("::")
        if not parent:
            out[scoped] = pose
        elif parent in gazebo_poses:
            # a link named like its model is the model's own body: keep the model's entry
            out.setdefault(name, compose(out.get(parent.rpartition("::")[2], gazebo_poses[parent]), pose))
    return out


def pose_errors(entities: list[dict], gazebo_poses: dict[str, tuple[float, ...]], only_dynamic: bool = False) -> list[str]:
    """One line per world.json entity that Gazebo does not show, or shows more than 1 mm / 1 mrad away."""
    found = world_poses(gazebo_poses)
    problems = []
    for entity in entities:
        if only_dynamic and entity["static"]:
            continue
        name = entity["name"]
        if name not in found:
            problems.append(f"{name}: not in Gazebo's poses")
            continue
        got = np.asarray(found[name], float)
        want_xyz = np.asarray(entity["pose"][:3], float)
        want_q = quat_from_rpy(*entity["pose"][3:])
        offset = float(np.linalg.norm(got[:3] - want_xyz))
        turn = 2 * math.acos(min(1.0, abs(float(np.dot(got[3:] / np.linalg.norm(got[3:]), want_q)))))
        if offset > POSITION_TOL or turn > ANGLE_TOL:
            problems.append(f"{name}: Gazebo {np.round(got, 5).tolist()} vs world.json {entity['pose']} "
                            f"({offset * 1000:.2f} mm, {turn * 1000:.2f} mrad)")
    return problems


def lidar_robot_sdf(lidar: dict, name: str = "robot", topic: str = "scan", height: float = 0.15,
                    samples: int | None = None) -> str:
    """A robot for the sensor checks: a low disc (``height`` tall, under the lidar) carrying a gpu_lidar at
    world.json's ``sensors.lidar`` height, with its rays (or ``samples`` over the same field of view) and
    range limits."""
    z = lidar["pose"][2]
    lidar = dict(lidar, samples=samples or lidar["samples"])
    return f"""<?xml version="1.0"?>
<sdf version="1.9">
  <model name="{name}">
    <link name="base">
      <pose>0 0 {height / 2} 0 0 0</pose>
      <inertial><mass>10</mass><inertia><ixx>0.1</ixx><iyy>0.1</iyy><izz>0.2</izz></inertia></inertial>
      <collision name="collision"><geometry><cylinder><radius>0.2</radius><length>{height}</length></cylinder></geometry></collision>
      <visual name="visual"><geometry><cylinder><radius>0.2</radius><length>{height}</length></cylinder></geometry></visual>
      <sensor name="lidar" type="gpu_lidar">
        <pose>0 0 {z - height / 2} 0 0 0</pose>
        <topic>{topic}</topic>
        <update_rate>10</update_rate>
        <always_on>true</always_on>
        <lidar>
          <scan><horizontal><samples>{lidar["samples"]}</samples><resolution>1</resolution>
            <min_angle>{lidar["angle_min"]}</min_angle><max_angle>{lidar["angle_max"]}</max_angle></horizontal></scan>
          <range><min>{lidar["range_min"]}</min><max>{lidar["range_max"]}</max><resolution>0.001</resolution></range>
        </lidar>
      </sensor>
    </link>
  </model>
</sdf>
"""


def scan_ranges(scan: dict, range_max: float) -> np.ndarray:
    """A LaserScan's ranges as floats, ``inf`` (no return) as ``range_max`` as world.json writes it."""
    ranges = np.array([float(v) for v in scan["ranges"]])
    return np.where(np.isfinite(ranges), ranges, range_max)


def scan_stamp(scan: dict) -> float:
    """A LaserScan's header stamp, s of simulation time (protobuf text leaves out a zero sec or nsec)."""
    from worldgen.sim import textproto

    stamp = textproto.first(textproto.first(scan, "header", {}), "stamp", {})
    return float(textproto.first(stamp, "sec", 0)) + float(textproto.first(stamp, "nsec", 0)) * 1e-9


def fit_circle(points: np.ndarray, radius: float, guess: np.ndarray) -> np.ndarray:
    """The centre of a circle of known ``radius`` through ``points`` ((k, 2)), least squares (Gauss-Newton)."""
    centre = np.asarray(guess, float).copy()
    for _ in range(50):
        offset = centre - points
        dist = np.linalg.norm(offset, axis=1)
        residual = dist - radius
        jac = offset / dist[:, None]
        step = np.linalg.lstsq(jac, -residual, rcond=None)[0]
        centre += step
        if np.linalg.norm(step) < 1e-9:
            break
    return centre


def seen_centres(scan: dict, pose: list[float], bodies: dict[str, tuple[np.ndarray, float]],
                 min_rays: int = 8) -> dict[str, tuple[np.ndarray, int]]:
    """Where a lidar scan taken at ``pose`` ([x, y, z, roll, pitch, yaw]) puts each upright cylinder of
    ``bodies`` (name -> (expected centre, radius)): the centre fitted to the returns that land within 10 cm
    of its expected surface, with the number of returns used (bodies with fewer than ``min_rays`` are left out)."""
    from worldgen.sim import textproto

    x, y, _, _, _, yaw = pose
    ranges = np.array([float(v) for v in scan["ranges"]])
    first, last = (float(textproto.first(scan, k)) for k in ("angle_min", "angle_max"))
    angles = yaw + np.linspace(first, last, len(ranges))
    hit = np.isfinite(ranges)
    points = np.column_stack([x + ranges * np.cos(angles), y + ranges * np.sin(angles)])
    out = {}
    for name, (centre, radius) in bodies.items():
        on = hit & (np.abs(np.linalg.norm(np.where(hit[:, None], points, 0.0) - centre, axis=1) - radius) < 0.10)
        if on.sum() >= min_rays:
            out[name] = (fit_circle(points[on], radius, centre), int(on.sum()))
    return out
