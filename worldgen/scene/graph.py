"""The scene graph: the one in-memory description every other layer reads.

Plain frozen data, no I/O and no knowledge of file formats. Poses are stored
relative to the parent node; world transforms and bounding boxes are derived on
demand, never stored twice.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, Iterable, Optional

import numpy as np

from worldgen.errors import SceneError
from worldgen.floats import round_float
from worldgen.scene.mover import Mover
from worldgen.scene.names import NAME_PATTERN
from worldgen.scene.pose import Pose
from worldgen.scene.robot import CLIMB_DEFAULTS, Robot
from worldgen.scene.shapes import Box, Cylinder, Mesh, Shape, Sphere, canonical_shape, unit_inertia

if TYPE_CHECKING:
    from worldgen.scene.terrain import Terrain

# Robot lives in worldgen.scene.robot; it is still importable from here, where it was first.
__all__ = ["ROLES", "Material", "Node", "Joint", "Scene", "Task", "Robot", "Physics", "NAME_PATTERN", "Mover",
           "CLIMB_DEFAULTS"]

#: Every role a node may have. Markers carry no collision geometry.
ROLES = ("floor", "wall", "obstacle", "door", "door_frame", "marker")


@dataclass(frozen=True)
class Material:
    """Surface properties. ``rgba`` in [0, 1]; ``friction`` is the Coulomb coefficient."""

    name: str = "default"
    rgba: tuple[float, float, float, float] = (0.7, 0.7, 0.7, 1.0)
    friction: float = 1.0

    def __post_init__(self):
        rgba = tuple(float(c) for c in self.rgba)
        if len(rgba) != 4 or not all(0.0 <= c <= 1.0 for c in rgba):
            raise SceneError(f"material rgba must be 4 values in [0, 1], got {self.rgba!r}")
        if not (math.isfinite(self.friction) and self.friction >= 0):
            raise SceneError(f"material friction must be >= 0, got {self.friction!r}")
        object.__setattr__(self, "rgba", rgba)
        object.__setattr__(self, "friction", float(self.friction))


@dataclass(frozen=True)
class Node:
    """One physical thing (or a pure frame when ``shape`` is None).

    ``pose`` is relative to ``parent`` (a node name, or None for the world).
    ``static`` things never move; a dynamic one has ``mass`` kg and an inertia
    derived from its shape (a solid of uniform density).
    """

    name: str
    role: str
    shape: Optional[Shape]
    pose: Pose = Pose()
    parent: Optional[str] = None
    static: bool = True
    mass: float = 1.0
    material: Material = Material()
    collision: bool = True

    def __post_init__(self):
        if not NAME_PATTERN.match(self.name):
            raise SceneError(f"node name {self.name!r} must match {NAME_PATTERN.pattern}")
        if self.role not in ROLES:
            raise SceneError(f"node {self.name!r}: role must be one of {', '.join(ROLES)}, got {self.role!r}")
        if not (math.isfinite(self.mass) and self.mass > 0):
            raise SceneError(f"node {self.name!r}: mass must be > 0 kg, got {self.mass!r}")
        if self.role == "marker" and self.collision:
            object.__setattr__(self, "collision", False)

    @property
    def inertia(self) -> tuple[float, float, float]:
        """Principal moments (ixx, iyy, izz) about the centre, kg m^2."""
        if self.shape is None:
            return (1e-6, 1e-6, 1e-6)
        ixx, iyy, izz = unit_inertia(self.shape)
        return (self.mass * ixx, self.mass * iyy, self.mass * izz)


@dataclass(frozen=True)
class Joint:
    """Connects ``child`` to ``parent``. ``kind`` is ``fixed`` or ``revolute``.

    The joint frame sits at ``pose`` in the child's frame (as SDF puts it);
    ``axis`` is expressed in the joint frame. ``initial`` is the joint's starting
    position (rad), ``limits`` (lo, hi) rad, ``damping`` N m s/rad.
    """

    name: str
    kind: str
    parent: str
    child: str
    pose: Pose = Pose()
    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    limits: tuple[float, float] = (0.0, 0.0)
    initial: float = 0.0
    damping: float = 0.0
    effort: float = 100.0
    velocity: float = 2.0

    def __post_init__(self):
        if not NAME_PATTERN.match(self.name):
            raise SceneError(f"joint name {self.name!r} must match {NAME_PATTERN.pattern}")
        if self.kind not in ("fixed", "revolute"):
            raise SceneError(f"joint {self.name!r}: kind must be fixed or revolute, got {self.kind!r}")
        lo, hi = self.limits
        if self.kind == "revolute" and not lo <= self.initial <= hi:
            raise SceneError(f"joint {self.name!r}: initial {self.initial} outside limits {self.limits}")


@dataclass(frozen=True)
class Task:
    """A spawn/goal pair for the robot. Poses lie on the floor (z = 0)."""

    id: str
    spawn: Pose
    goal: Pose
    goal_tolerance: float = 0.2


@dataclass(frozen=True)
class Physics:
    """World-level simulation settings, written into every format that can hold them.

    ``step_size`` s; ``real_time_factor`` for Gazebo (0 = as fast as possible);
    ``gravity`` m/s^2 as (gx, gy, gz).
    """

    step_size: float = 0.002
    real_time_factor: float = 1.0
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)

    def __post_init__(self):
        if not (math.isfinite(self.step_size) and self.step_size > 0):
            raise SceneError(f"physics step_size must be > 0 s, got {self.step_size!r}")
        if not (math.isfinite(self.real_time_factor) and self.real_time_factor >= 0):
            raise SceneError(f"physics real_time_factor must be >= 0, got {self.real_time_factor!r}")


@dataclass(frozen=True, eq=False)
class Scene:
    """Nodes, joints and the floor area robots may use.

    ``bounds`` is ((minx, miny), (maxx, maxy)) in metres. Nodes keep the order
    the generator gave them; that order is part of the canonical form.
    ``movers`` are dynamic obstacles on scripted paths (:class:`Mover`); their
    names share one scope with the nodes' and joints'.
    """

    nodes: tuple[Node, ...]
    joints: tuple[Joint, ...] = ()
    bounds: tuple[tuple[float, float], tuple[float, float]] = ((-5.0, -5.0), (5.0, 5.0))
    physics: Physics = Physics()
    movers: tuple[Mover, ...] = ()
    terrain: Optional["Terrain"] = None

    def __post_init__(self):
        object.__setattr__(self, "nodes", tuple(self.nodes))
        object.__setattr__(self, "joints", tuple(self.joints))
        object.__setattr__(self, "movers", tuple(self.movers))
        names = [n.name for n in self.nodes]
        seen: set[str] = set()
        for name in names:
            if name in seen:
                raise SceneError(f"node name {name!r} is used twice; names must be unique")
            seen.add(name)
        for node in self.nodes:
            if node.parent is not None and node.parent not in seen:
                raise SceneError(f"node {node.name!r} has unknown parent {node.parent!r}")
        for joint in self.joints:
            for end in (joint.parent, joint.child):
                if end != "world" and end not in seen:
                    raise SceneError(f"joint {joint.name!r} names unknown node {end!r}")
        (x0, y0), (x1, y1) = self.bounds
        if not (x1 > x0 and y1 > y0):
            raise SceneError(f"scene bounds must have min < max, got {self.bounds!r}")
        self._check_acyclic()
        taken = seen | {j.name for j in self.joints}
        for mover in self.movers:
            if mover.name in taken:
                raise SceneError(f"mover name {mover.name!r} is already used by a node, joint or mover")
            taken.add(mover.name)

    def _check_acyclic(self):
        parents = {n.name: n.parent for n in self.nodes}
        for name in parents:
            seen = set()
            while name is not None:
                if name in seen:
                    raise SceneError(f"node {name!r} is its own ancestor")
                seen.add(name)
                name = parents[name]

    @cached_property
    def _by_name(self) -> dict[str, Node]:
        return {n.name: n for n in self.nodes}

    def node(self, name: str) -> Node:
        return self._by_name[name]

    def __iter__(self):
        return iter(self.nodes)

    def __len__(self):
        return len(self.nodes)

    def children(self, name: Optional[str]) -> list[Node]:
        return [n for n in self.nodes if n.parent == name]

    def world_matrix(self, name: str) -> np.ndarray:
        """(4, 4) transform of node ``name`` in the world frame."""
        cache = self._world_cache
        if name not in cache:
            node = self._by_name[name]
            local = node.pose.matrix()
            cache[name] = local if node.parent is None else self.world_matrix(node.parent) @ local
        return cache[name]

    @cached_property
    def _world_cache(self) -> dict[str, np.ndarray]:
        return {}

    def world_pose(self, name: str) -> Pose:
        from worldgen.scene.pose import matrix_to_pose

        node = self._by_name[name]
        if node.parent is None:
            return node.pose
        return matrix_to_pose(self.world_matrix(name))

    def aabb(self, name: str) -> np.ndarray:
        """(2, 3) world-frame axis-aligned box [[min], [max]] of node ``name``'s shape (read-only)."""
        if name not in self._aabb_cache:
            self._fill_aabbs([name])
        return self._aabb_cache[name]

    def aabbs(self, names) -> np.ndarray:
        """(n, 2, 3) :meth:`aabb` of each named node; those not yet known made together."""
        cache = self._aabb_cache
        self._fill_aabbs([name for name in names if name not in cache])
        return np.array([cache[name] for name in names], dtype=float).reshape(-1, 2, 3)

    @cached_property
    def _aabb_cache(self) -> dict[str, np.ndarray]:
        return {}

    def _fill_aabbs(self, names) -> None:
        """Remember the world boxes of ``names``: boxes and cylinders each in one vectorised pass (tight:
        a box's half extents through |R|, a cylinder's |a_i| h/2 + r sqrt(1 - a_i^2) along world axis i)."""
        shapes = {name: self._by_name[name].shape for name in names}
        boxes = {name: s for name, s in shapes.items() if isinstance(s, Box)}
        if boxes:
            m = np.stack([self.world_matrix(name) for name in boxes])
            half = np.array([s.size for s in boxes.values()], dtype=np.float64) / 2.0
            self._cache_boxes(list(boxes), m[:, :3, 3], np.einsum("kij,kj->ki", np.abs(m[:, :3, :3]), half))
        cylinders = {name: s for name, s in shapes.items() if isinstance(s, Cylinder)}
        if cylinders:
            m = np.stack([self.world_matrix(name) for name in cylinders])
            length = np.array([s.length for s in cylinders.values()], dtype=np.float64)
            radius = np.array([s.radius for s in cylinders.values()], dtype=np.float64)
            axis = m[:, :3, 2]
            reach = np.abs(axis) * length[:, None] / 2 + radius[:, None] * np.sqrt(np.clip(1 - axis**2, 0, 1))
            self._cache_boxes(list(cylinders), m[:, :3, 3], reach)
        for name in names:
            if name in self._aabb_cache:
                continue
            node, m = self._by_name[name], self.world_matrix(name)
            if node.shape is None:
                self._cache_boxes([name], m[None, :3, 3], np.zeros((1, 3)))
            elif isinstance(node.shape, Mesh):  # tight: the turned vertices, not a turned box
                pts = node.shape.scaled_vertices() @ m[:3, :3].T + m[:3, 3]
                self._remember(name, pts.min(axis=0), pts.max(axis=0))
            elif isinstance(node.shape, Sphere):  # boxes and cylinders were cached above
                self._cache_boxes([name], m[None, :3, 3], np.full((1, 3), node.shape.radius))

    def _cache_boxes(self, names, centres: np.ndarray, reaches: np.ndarray) -> None:
        for name, centre, reach in zip(names, centres, reaches):
            self._remember(name, centre - reach, centre + reach)

    def _remember(self, name: str, lo: np.ndarray, hi: np.ndarray) -> None:
        box = np.array([lo, hi])
        box.flags.writeable = False
        self._aabb_cache[name] = box

    def colliders(self) -> list[Node]:
        """Nodes with collision geometry that a robot on the floor can hit (the floor excluded)."""
        return [n for n in self.nodes if n.shape is not None and n.collision and n.role != "floor"]

    def meshes(self) -> list[Mesh]:
        return [n.shape for n in self.nodes if isinstance(n.shape, Mesh)]

    def canonical(self) -> dict:
        """A plain, rounded description of everything that makes this world what it is."""
        return {
            "bounds": [[round_float(v) for v in corner] for corner in self.bounds],
            "nodes": [_canonical_node(n) for n in self.nodes],
            "joints": [_canonical_joint(j) for j in self.joints],
            "physics": {
                "step_size": round_float(self.physics.step_size),
                "real_time_factor": round_float(self.physics.real_time_factor),
                "gravity": [round_float(g) for g in self.physics.gravity],
            },
            # Only where there are movers, so that worlds without any keep their hashes.
            **({"movers": [m.canonical() for m in self.movers]} if self.movers else {}),
            # Only on terrain, so that flat worlds keep their hashes.
            **({"terrain": self.terrain.canonical()} if self.terrain is not None else {}),
        }

    def content_hash(self) -> str:
        """``sha256:<hex>`` of the canonical description; equal hashes mean equal worlds."""
        text = json.dumps(self.canonical(), sort_keys=True, separators=(",", ":"))
        return "sha256:" + hashlib.sha256(text.encode()).hexdigest()

    def with_nodes(self, nodes: Iterable[Node]) -> "Scene":
        return Scene(tuple(nodes), self.joints, self.bounds, self.physics, self.movers, self.terrain)

    def with_movers(self, movers: Iterable[Mover]) -> "Scene":
        return Scene(self.nodes, self.joints, self.bounds, self.physics, tuple(movers), self.terrain)

    def with_terrain(self, terrain: Optional["Terrain"]) -> "Scene":
        return Scene(self.nodes, self.joints, self.bounds, self.physics, self.movers, terrain)


def _canonical_node(n: Node) -> dict:
    return {
        "name": n.name,
        "role": n.role,
        "parent": n.parent,
        "pose": [round_float(v) for v in n.pose.as_list()],
        "shape": canonical_shape(n.shape),
        "static": n.static,
        "mass": round_float(n.mass),
        "collision": n.collision,
        "material": {
            "name": n.material.name,
            "rgba": [round_float(c) for c in n.material.rgba],
            "friction": round_float(n.material.friction),
        },
    }


def _canonical_joint(j: Joint) -> dict:
    return {
        "name": j.name,
        "kind": j.kind,
        "parent": j.parent,
        "child": j.child,
        "pose": [round_float(v) for v in j.pose.as_list()],
        "axis": [round_float(v) for v in j.axis],
        "limits": [round_float(v) for v in j.limits],
        "initial": round_float(j.initial),
        "damping": round_float(j.damping),
    }
