"""Scene -> ``world.usda``: the world as an OpenUSD stage for Isaac Sim / Isaac Lab (docs/formats.md).

One text layer (``#usda 1.0``), Z up, metres and kilograms (``upAxis = "Z"``, ``metersPerUnit = 1``,
``kilogramsPerUnit = 1``), default prim ``/World``:

* ``/World/PhysicsScene``: a ``PhysicsScene`` with the scene's gravity (direction and magnitude).
* ``/World/PhysicsMaterials/mu_<friction>``: one ``Material`` with ``PhysicsMaterialAPI`` per friction
  the world uses (static = dynamic friction = the Coulomb coefficient, no restitution), bound to each
  collider through ``material:binding:physics``.
* ``/World/<node>/.../<child node>``: every node an ``Xform`` at its pose relative to its parent
  (``translate`` then ``orient``, as Isaac Sim expects), holding its shape as a child prim ``shape``: a
  unit ``Cube`` scaled to a box's full extents, a ``Cylinder`` along z, a ``Sphere``, or a ``Mesh``.
  A collider has ``PhysicsCollisionAPI``. Static nodes have no rigid body: UsdPhysics (and PhysX) take
  a collider without one as static. A dynamic node (a door leaf) is a rigid body with its mass, its
  diagonal inertia and its centre of mass.
* A door hinge: a ``PhysicsRevoluteJoint`` under the leaf, ``body0`` the leaf's parent (the door's
  head, a static collider, as in UsdPhysics' own examples) and ``body1`` the leaf. UsdPhysics names a
  revolute axis X, Y or Z of the joint frame, so the frame's z is turned onto the scene's axis.
  Unlike SDF (whose link poses are the joint's zero, :mod:`worldgen.export.sdf`), the joint's two
  frames fix the zero themselves: ``localRot0`` is the hinge with the door closed, ``localRot1`` the
  hinge on the leaf as it stands, so the angle PhysX reads at the start is world.json's
  ``doors[].angle`` and the limits are the scene's own (degrees, as UsdPhysics measures angles).
  Joint damping is an angular ``PhysicsDriveAPI`` with no stiffness (its damping is per degree).
  A dynamic node on a fixed joint, or under a parent with no joint, is fixed to it with a
  ``PhysicsFixedJoint``; a dynamic root with no joint is a free body (as in the SDF).
* ``/World/Movers/<name>``, ``/World/People/<name>``, ``/World/Tasks/<task id>/spawn|goal``: see
  :mod:`worldgen.export.usd_motion`.

Not carried (no UsdPhysics property holds them): the physics step size and real-time factor (PhysX's
own schema, or the simulation's settings in Isaac), joint effort and velocity limits.
"""

from __future__ import annotations

import math
from typing import Optional, Sequence

import numpy as np

from worldgen.errors import WorldgenError
from worldgen.export.usd_motion import TIME_CODES_PER_SECOND, write_movers, write_tasks
from worldgen.export.usd_prims import SHAPE_PRIM, Specs, matrix_quaternion, quaternion, require_pxr
from worldgen.files import USDC_NAME
from worldgen.floats import fmt, round_float
from worldgen.scene import Mesh, Node, Scene
from worldgen.scene.graph import Joint, Task
from worldgen.scene.ground import ground_scene

__all__ = ["to_usd", "to_usdc", "RESERVED", "SHAPE_PRIM", "MIN_MOMENT", "material_name"]

#: Names of /World's own children, and the shape prim's: no node may take them.
RESERVED = ("PhysicsScene", "PhysicsMaterials", "Movers", "People", "Tasks", SHAPE_PRIM)
#: Smallest principal moment written (kg m^2), as in the SDF: a zero moment is no valid inertia.
MIN_MOMENT = 1e-6


def material_name(friction: float) -> str:
    """The physics material's prim name for a Coulomb ``friction``: ``mu_0_8`` for 0.8."""
    return "mu_" + fmt(friction).replace(".", "_")


def to_usd(scene: Scene, name: str = "default", tasks: Sequence[Task] = (), duration: float = 0.0) -> bytes:
    """The USD stage of ``scene`` as ``.usda`` text (UTF-8 bytes); see the module docstring.

    ``tasks`` become named Xforms for scripts to find; ``duration`` (s) is how long looping movers
    are played out for (USD has no looping time samples), at least one period each.
    """
    return _layer(scene, name, tasks, duration).ExportToString().encode()


def to_usdc(scene: Scene, name: str = "default", tasks: Sequence[Task] = (), duration: float = 0.0) -> bytes:
    """The same stage as :func:`to_usd`, in USD's binary crate form (``.usdc``)."""
    import tempfile
    from pathlib import Path

    layer = _layer(scene, name, tasks, duration)
    with tempfile.TemporaryDirectory(prefix="worldgen-usdc-") as folder:
        path = Path(folder) / USDC_NAME  # usd-core writes a crate file only to a path, by its extension
        if not layer.Export(str(path)):
            raise WorldgenError(f"usd-core could not write {path.name}")
        return path.read_bytes()


def _layer(scene: Scene, name: str, tasks: Sequence[Task], duration: float):
    pxr = require_pxr()
    scene = ground_scene(scene)  # the terrain as one mesh collider; the scene itself on flat ground
    taken = [n.name for n in scene.nodes if n.name in RESERVED] + [j.name for j in scene.joints if j.name == SHAPE_PRIM]
    if taken:
        raise WorldgenError(f"the USD exporter reserves the names {', '.join(RESERVED)}; "
                            f"the scene uses {', '.join(sorted(set(taken)))}")
    specs = Specs(pxr)
    with pxr.Sdf.ChangeBlock():
        root = specs.layer.pseudoRoot
        world = specs.prim(None, "World", "Xform")
        root.SetInfo("defaultPrim", "World")
        root.SetInfo("upAxis", "Z")
        root.SetInfo("metersPerUnit", 1.0)
        root.SetInfo("kilogramsPerUnit", 1.0)
        root.SetInfo("customLayerData", {"worldgen:world": name})
        _physics_scene(specs, world, scene)
        materials = _materials(specs, world, scene)
        _NodeWriter(specs, scene, materials).write_all(world)
        end = write_movers(specs, world, scene.movers, materials, duration)
        write_tasks(specs, world, tasks)
        root.SetInfo("timeCodesPerSecond", float(TIME_CODES_PER_SECOND))
        root.SetInfo("framesPerSecond", float(TIME_CODES_PER_SECOND))
        root.SetInfo("startTimeCode", 0.0)
        root.SetInfo("endTimeCode", end)
    return specs.layer


def _physics_scene(specs: Specs, world, scene: Scene) -> None:
    g = np.asarray(scene.physics.gravity, dtype=float)
    magnitude = float(np.linalg.norm(g))
    prim = specs.prim(world, "PhysicsScene", "PhysicsScene")
    direction = g / magnitude if magnitude > 0 else np.array([0.0, 0.0, -1.0])
    specs.attr(prim, "physics:gravityDirection", "Vector3f", specs.vec3(direction, "Float3"))
    specs.attr(prim, "physics:gravityMagnitude", "Float", round_float(magnitude))


def _materials(specs: Specs, world, scene: Scene) -> dict[float, str]:
    """One physics material per friction used, in the order first used: friction -> prim path."""
    frictions = [n.material.friction for n in scene.nodes if n.shape is not None and n.collision]
    frictions += [m.friction for m in scene.movers]
    paths: dict[float, str] = {}
    if not frictions:
        return paths
    scope = specs.prim(world, "PhysicsMaterials", "Scope")
    for mu in frictions:
        if mu in paths:
            continue
        label = material_name(mu)
        prim = specs.prim(scope, label, "Material", ["PhysicsMaterialAPI"])
        specs.attr(prim, "physics:staticFriction", "Float", round_float(mu))
        specs.attr(prim, "physics:dynamicFriction", "Float", round_float(mu))
        specs.attr(prim, "physics:restitution", "Float", 0.0)
        paths[mu] = f"/World/PhysicsMaterials/{label}"
    return paths


def _turn_z_onto(axis) -> np.ndarray:
    """(3, 3) rotation taking +z onto the unit ``axis`` (the shortest turn; half a turn about x for -z)."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    c = float(a[2])
    if c > 1 - 1e-12:
        return np.eye(3)
    if c < -1 + 1e-12:
        return np.diag([1.0, -1.0, -1.0])
    k = np.array([-a[1], a[0], 0.0]) / math.sqrt(1 - c * c)  # z x a, normalised
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sqrt(1 - c * c) * kx + (1 - c) * (kx @ kx)


def _turn_about_z(angle: float) -> np.ndarray:
    m = np.eye(4)
    m[:2, :2] = [[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]]
    return m


class _NodeWriter:
    """Writes every node depth first (children in scene order), then the joints of its rigid bodies."""

    def __init__(self, specs: Specs, scene: Scene, materials: dict[float, str]):
        self.specs, self.scene, self.materials = specs, scene, materials
        self.children: dict[Optional[str], list[Node]] = {}
        for node in scene.nodes:
            self.children.setdefault(node.parent, []).append(node)
        self.joint_of = {j.child: j for j in scene.joints}
        self.paths: dict[str, str] = {}

    def write_all(self, world) -> None:
        bodies: list[tuple[Node, object]] = []
        stack = [(world, "/World", node, False) for node in reversed(self.children.get(None, []))]
        while stack:
            parent, parent_path, node, in_body = stack.pop()
            rigid = not node.static
            if rigid and in_body:
                raise WorldgenError(f"the USD exporter cannot nest dynamic node {node.name!r} in another dynamic node")
            prim = self._node(parent, node, rigid)
            path = self.paths[node.name] = f"{parent_path}/{node.name}"
            if rigid:
                bodies.append((node, prim))
            stack.extend((prim, path, child, in_body or rigid) for child in reversed(self.children.get(node.name, [])))
        for joint in self.scene.joints:
            if joint.kind == "revolute" and self.scene.node(joint.child).static:
                raise WorldgenError(f"the USD exporter needs revolute joint {joint.name!r}'s child "
                                    f"{joint.child!r} to be dynamic (a static child cannot turn)")
        for node, prim in bodies:
            held = self.joint_of.get(node.name)
            if held is not None and held.kind == "revolute":
                self._revolute(prim, held)
            elif held is not None or node.parent is not None:
                # Held to its parent (or to the world) as the SDF holds it; a root with no joint is a free body.
                self._fixed(prim, node, held.name if held is not None else f"{node.name}_fixed")

    def _node(self, parent, node: Node, rigid: bool):
        specs = self.specs
        prim = specs.prim(parent, node.name, "Xform", ["PhysicsRigidBodyAPI", "PhysicsMassAPI"] if rigid else [])
        pose = node.pose
        specs.transform(prim, pose.position, quaternion(pose.roll, pose.pitch, pose.yaw))
        if rigid:
            centre = np.zeros(3)
            if isinstance(node.shape, Mesh):  # the moments are the bounding box's, about its centre
                v = node.shape.scaled_vertices()
                centre = (v.min(axis=0) + v.max(axis=0)) / 2.0
            specs.attr(prim, "physics:mass", "Float", round_float(node.mass))
            specs.attr(prim, "physics:diagonalInertia", "Float3",
                       specs.vec3([max(i, MIN_MOMENT) for i in node.inertia], "Float3"))
            specs.attr(prim, "physics:centerOfMass", "Point3f", specs.vec3(centre, "Float3"))
            # The moments are about the node's own axes; UsdPhysics wants the axes said with the moments.
            specs.attr(prim, "physics:principalAxes", "Quatf", specs.quat((1.0, 0.0, 0.0, 0.0), double=False))
        if node.shape is not None:
            material = self.materials[node.material.friction] if node.collision else None
            specs.shape(prim, node.shape, node.material.rgba, material, rigid, SHAPE_PRIM)
        return prim

    def _ends(self, prim, joint_parent: str, child: str) -> None:
        if joint_parent != "world":
            self.specs.rel(prim, "physics:body0", self.paths[joint_parent])
        self.specs.rel(prim, "physics:body1", self.paths[child])

    def _frames(self, prim, frame0: np.ndarray, frame1: np.ndarray) -> None:
        specs = self.specs
        specs.attr(prim, "physics:localPos0", "Point3f", specs.vec3(frame0[:3, 3], "Float3"))
        specs.attr(prim, "physics:localRot0", "Quatf", specs.quat(matrix_quaternion(frame0[:3, :3]), double=False))
        specs.attr(prim, "physics:localPos1", "Point3f", specs.vec3(frame1[:3, 3], "Float3"))
        specs.attr(prim, "physics:localRot1", "Quatf", specs.quat(matrix_quaternion(frame1[:3, :3]), double=False))

    def _parent_matrix(self, parent: str) -> np.ndarray:
        return np.eye(4) if parent == "world" else self.scene.world_matrix(parent)

    def _revolute(self, body, joint: Joint) -> None:
        specs = self.specs
        damped = joint.damping > 0
        prim = specs.prim(body, joint.name, "PhysicsRevoluteJoint", ["PhysicsDriveAPI:angular"] if damped else [])
        self._ends(prim, joint.parent, joint.child)
        specs.attr(prim, "physics:axis", "Token", "Z", uniform=True)
        # The hinge on the leaf: the scene's joint frame with its z turned onto the joint's axis.
        frame1 = joint.pose.matrix()
        frame1[:3, :3] = frame1[:3, :3] @ _turn_z_onto(joint.axis)
        # The hinge on the parent: where that frame is with the joint at 0 (the leaf turned back by `initial`).
        hinge_closed = self.scene.world_matrix(joint.child) @ frame1 @ _turn_about_z(-joint.initial)
        frame0 = np.linalg.inv(self._parent_matrix(joint.parent)) @ hinge_closed
        self._frames(prim, frame0, frame1)
        specs.attr(prim, "physics:lowerLimit", "Float", round_float(math.degrees(joint.limits[0])))
        specs.attr(prim, "physics:upperLimit", "Float", round_float(math.degrees(joint.limits[1])))
        if damped:
            specs.attr(prim, "drive:angular:physics:type", "Token", "force", uniform=True)
            specs.attr(prim, "drive:angular:physics:stiffness", "Float", 0.0)
            specs.attr(prim, "drive:angular:physics:damping", "Float", round_float(math.radians(joint.damping)))

    def _fixed(self, body, node: Node, name: str) -> None:
        joint = self.joint_of.get(node.name)
        parent = joint.parent if joint is not None else node.parent
        assert parent is not None, "called for a node with a joint or a parent"
        prim = self.specs.prim(body, name, "PhysicsFixedJoint")
        self._ends(prim, parent, node.name)
        child_in_parent = np.linalg.inv(self._parent_matrix(parent)) @ self.scene.world_matrix(node.name)
        self._frames(prim, child_in_parent, np.eye(4))
