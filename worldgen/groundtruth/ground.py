"""What the oracles take: a world (its world.json, and FCL colliders built once, on first use) and a
recorded trajectory, checked (:func:`as_trajectory`).

A world is a :class:`~worldgen.World` (its scene is used), a world of a built pack
(:class:`~worldgen.PackWorld`, folder or archive) or a written world folder, each read through
:func:`worldgen.groundtruth.folder.open_world`; without a scene the colliders are rebuilt from
world.json's entities, exactly as the feasibility check places them.
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable, Optional

import numpy as np

from worldgen.errors import ParameterError
from worldgen.groundtruth.folder import open_world, robot_of, task_of

__all__ = ["Ground", "load", "leaves_of", "as_trajectory"]


class Ground:
    """What the oracles need of one world: world.json, and FCL colliders built once (on first use).

    ``path`` is the world's folder on disk where it has one (the judge reads its scenario.yaml there)."""

    def __init__(self, meta: dict, scene=None, read: Optional[Callable[[str], bytes]] = None,
                 path: Optional[Path] = None):
        self.meta = meta
        self._scene = scene
        self._read = read  # a file of the world by its relative path (meshes), where there is no scene
        self.path = path
        self._colliders = None
        self._fixed_colliders = None

    @property
    def robot(self):
        return robot_of(self.meta)

    def task(self, task: Optional[str] = None) -> dict:
        return task_of(self.meta, task)

    @property
    def colliders(self):
        if self._colliders is None:
            from worldgen.feasibility.collision import Colliders
            self._colliders = Colliders(self._scene) if self._scene is not None else _entity_colliders(self.meta, self._read)
        return self._colliders

    @property
    def fixed_colliders(self):
        """The colliders less the door leaves and what hangs on them: what no robot moves by pushing."""
        leaves = leaves_of(self)
        if not leaves:
            return self.colliders
        if self._fixed_colliders is None:
            from worldgen.feasibility.collision import Colliders
            if self._scene is not None:
                from worldgen.scene import Scene
                scene = self._scene
                kept = tuple(n for n in scene.nodes if not _on_leaf(scene, n, leaves))
                names = {n.name for n in kept} | {"world"}
                joints = tuple(j for j in scene.joints if j.parent in names and j.child in names)
                self._fixed_colliders = Colliders(Scene(kept, joints, scene.bounds, scene.physics, scene.movers, scene.terrain))
            else:
                meta = dict(self.meta, entities=[e for e in self.meta["entities"] if e["name"] not in leaves])
                self._fixed_colliders = _entity_colliders(meta, self._read)
        return self._fixed_colliders


def load(world) -> Ground:
    """A :class:`Ground` for a World, a PackWorld, a world folder (str/Path) or a Ground (returned as is)."""
    if isinstance(world, Ground):
        return world
    opened = open_world(world)
    return Ground(opened.metadata, scene=opened.scene, read=opened.read, path=opened.path)


def leaves_of(ground: Ground) -> frozenset:
    """The names of the world's door leaves (world.json ``doors[].name``)."""
    return frozenset(str(d["name"]) for d in ground.meta.get("doors") or [])


def _on_leaf(scene, node, leaves) -> bool:
    """Whether ``node`` is a door leaf or hangs on one (a handle)."""
    while node is not None:
        if node.name in leaves:
            return True
        node = scene.node(node.parent) if node.parent else None
    return False


def _entity_colliders(meta: dict, read: Callable[[str], bytes]):
    """The same Colliders the feasibility check uses, rebuilt from world.json's entities."""
    from worldgen.scene import Box, Cylinder, Mesh, Node, Pose, Scene, Shape, Sphere

    nodes = []
    for e in meta["entities"]:
        if e["role"] in ("floor", "marker"):
            continue
        s = e["shape"]
        shape: Shape
        if s["type"] == "box":
            shape = Box(tuple(s["size"]))
        elif s["type"] == "cylinder":
            shape = Cylinder(s["radius"], s["length"])
        elif s["type"] == "sphere":
            shape = Sphere(s["radius"])
        else:
            import io

            import trimesh
            mesh = trimesh.load(io.BytesIO(read(s["uri"])), file_type=Path(s["uri"]).suffix.lstrip("."), force="mesh")
            assert isinstance(mesh, trimesh.Trimesh), "force='mesh' loads one Trimesh"
            shape = Mesh(s["uri"], np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=np.int64),
                         tuple(s.get("scale", (1.0, 1.0, 1.0))))
        # world.json poses are world-frame, so every node becomes a root node here.
        nodes.append(Node(e["name"], e["role"], shape, Pose(*e["pose"])))
    from worldgen.feasibility.collision import Colliders
    return Colliders(Scene(tuple(nodes)))


def as_trajectory(trajectory) -> np.ndarray:
    """(n, 3) float array ``t, x, y`` of a recorded run; ParameterError with one line otherwise."""
    try:
        a = np.asarray(trajectory, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError("parameter 'trajectory' must be an (n, 3) or (n, 4) array of numbers (t, x, y[, yaw])") from None
    if a.ndim != 2 or a.shape[1] not in (3, 4) or len(a) < 1:
        raise ParameterError(f"parameter 'trajectory' must be an (n, 3) or (n, 4) array (t, x, y[, yaw]) with n >= 1, "
                             f"got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ParameterError("parameter 'trajectory' must hold finite numbers only, got NaN or inf")
    if np.any(np.diff(a[:, 0]) < 0):
        raise ParameterError("parameter 'trajectory' must have non-decreasing times (column 0)")
    return a[:, :3].copy()
