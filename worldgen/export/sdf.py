"""Scene -> SDFormat world, as version 1.9 (Gazebo Fortress to Harmonic) or 1.6 (Gazebo classic).

The world is filled into the skeleton ``templates/world.sdf`` (physics, scene,
one directional light; no ``model://`` includes and no ground plane, because the
floor is a node of the scene). Each root node becomes ``<model name=node.name>``
posed in the world; the node and its descendants become links of that model,
each link named after its node, joined by the scene's Joint that names the
child, or by a fixed joint when none does.

What differs between the two targets, and why the output looks as it does
(checked against the SDFormat specs shipped with libsdformat 12 and the
simulators' sources):

* SDF 1.6 predates pose frame semantics (1.8: ``<pose relative_to>``,
  ``<xyz expressed_in>``) and has no light ``<intensity>``. A 1.6 file that
  used them would be rejected by a 1.6 parser (Gazebo classic uses libsdformat
  6 or 9), so in 1.6 a child link's pose is computed here in its model's frame,
  while in 1.9 it is written relative to its parent link, exactly as the scene
  stores it. Both are checked by ``tests/tools/sdf_check.cc``, which parses a
  1.6 file against the 1.6 spec before converting it.
* Pacing: Gazebo classic runs ``real_time_update_rate`` physics steps per wall
  second (0 = as fast as it can) and does not pace by ``real_time_factor``;
  Gazebo Sim paces by ``real_time_factor`` (period = step / factor, and a factor
  of 0 drops the wait) and ignores the update rate. Both are written, kept
  consistent: rate = factor / step, so ``real_time_factor=0`` means
  "unthrottled" in every Gazebo.
* Friction is ``surface/friction/ode/mu`` and ``mu2`` in both versions; Gazebo
  classic's ODE and Gazebo Sim's physics plugins both read that block.
* Initial joint angle: no version carries it portably. 1.6 defines
  ``axis/initial_position`` but Gazebo classic ignores it (gazebo-classic issue
  2694); 1.8 deprecates it, 1.9 removes it, and libsdformat 12 rejects it in a
  1.6 file once converted. In SDF the link poses *are* the joint's zero, so the
  scene's poses (which show a jointed child at its initial angle, e.g. a door
  ajar) are written as they are, and the limits are shifted to keep the same
  physical range: ``lower = lo - initial``, ``upper = hi - initial``. The world
  therefore loads looking exactly like world.json and the other formats; only
  the joint position Gazebo reports is offset: it reads ``angle - initial``
  (world.json's ``doors[].angle`` is the initial angle).
* Mesh ``<uri>`` is the scene's path relative to the world folder. Gazebo Sim
  resolves a relative uri against the SDF file's folder; Gazebo classic looks it
  up on its resource path, so add the world folder to ``GAZEBO_RESOURCE_PATH``.
* No ``<plugin>``: Gazebo Sim loads its default systems (physics, scene
  broadcaster, user commands) when a world names none.
* Movers (``scene.movers``) are ``<actor>``s with a looping scripted
  trajectory and a link carrying their cylinder, the same element in 1.6 and
  1.9 (:mod:`worldgen.export.movers`). Gazebo classic moves any actor link
  along the script; Gazebo Sim accepts skin-less, trajectory-only actors only
  since gz-sim pull request 1947 (2023) and may not draw their links (gz-sim
  issue 418). Neither gives actors contacts: a mover is seen, not felt.

A model is ``<static>`` only when all its nodes are static. A static root with a
dynamic descendant (a door frame with its leaf) gives a dynamic model whose root
link is welded to the world by a fixed joint, so that the leaf can swing.
"""

from __future__ import annotations

from typing import Optional

import numpy as np
from lxml import etree

from worldgen.errors import ParameterError, WorldgenError
from worldgen.export.movers import write_sdf_actors
from worldgen.export.xml import load_template
from worldgen.floats import fmt, fmt_seq
from worldgen.scene import Box, Cylinder, Mesh, Node, Pose, Scene, Sphere, matrix_to_pose
from worldgen.scene.graph import Joint

__all__ = ["SDF_VERSIONS", "TEMPLATE", "MIN_MOMENT", "to_sdf"]

#: Versions this exporter writes: 1.9 for Gazebo Fortress-Harmonic, 1.6 for Gazebo classic.
SDF_VERSIONS = ("1.9", "1.6")
TEMPLATE = "world.sdf"
#: Smallest principal moment written (kg m^2): floats keep 6 decimals, and a
#: moment rounded to 0 would make the inertia invalid for every physics engine.
MIN_MOMENT = 1e-6


def to_sdf(scene: Scene, version: str = "1.9", name: str = "default") -> etree._ElementTree:
    """The SDFormat world of ``scene`` as an lxml tree (see the module docstring).

    ``name`` is the world's name; SDFormat 1.8+ reserves ``world`` and names
    starting with ``__``, so the default is Gazebo's usual ``default``.
    """
    if version not in SDF_VERSIONS:
        raise ParameterError(f"parameter 'sdf_version' must be one of {', '.join(SDF_VERSIONS)}, got {version!r}")
    if not name or name == "world" or name.startswith("__"):
        raise ParameterError(f"parameter 'name' must be a non-empty SDF world name other than 'world' "
                             f"and not starting with '__', got {name!r}")
    if "world" in {n.name for n in scene.nodes}:
        raise WorldgenError("no node may be named 'world': SDFormat reserves that name for the world frame")
    tree = load_template(TEMPLATE)
    root = tree.getroot()
    root.set("version", version)
    world = root.find("world")
    world.set("name", name)
    _fill_physics(world, scene)
    writer = _ModelWriter(scene, version)
    for node in scene.nodes:
        if node.parent is None:
            writer.write(world, node)
    write_sdf_actors(world, scene)
    return tree


def _fill_physics(world, scene: Scene) -> None:
    physics = scene.physics
    block = world.find("physics")
    block.find("max_step_size").text = fmt(physics.step_size)
    block.find("real_time_factor").text = fmt(physics.real_time_factor)
    block.find("real_time_update_rate").text = fmt(physics.real_time_factor / physics.step_size)
    world.find("gravity").text = fmt_seq(physics.gravity)


class _ModelWriter:
    """Writes one model per root node; holds the lookups every model needs, built once."""

    def __init__(self, scene: Scene, version: str):
        self.scene = scene
        self.frames = version != "1.6"  # pose relative_to exists from SDF 1.8 on
        self.children: dict[str, list[Node]] = {}
        for node in scene.nodes:
            if node.parent is not None:
                self.children.setdefault(node.parent, []).append(node)
        self.joint_of: dict[str, Joint] = {}
        for joint in scene.joints:
            if joint.child in self.joint_of:
                raise WorldgenError(f"node {joint.child!r} is the child of two joints; SDF allows one")
            self.joint_of[joint.child] = joint
        # Every name a generated joint must avoid: links and joints share a model's name scope.
        self.taken = {n.name for n in scene.nodes} | {j.name for j in scene.joints}
        self.surfaces: dict[float, etree._Element] = {}
        self.materials: dict[tuple, etree._Element] = {}

    def subtree(self, root: Node) -> list[Node]:
        """``root`` and its descendants, depth first, children in scene order."""
        out, stack = [], [root]
        while stack:
            node = stack.pop()
            out.append(node)
            stack.extend(reversed(self.children.get(node.name, ())))
        return out

    def write(self, world, root: Node) -> None:
        nodes = self.subtree(root)
        static = all(n.static for n in nodes)
        model = _el(world, "model", name=root.name)
        _el(model, "static", "true" if static else "false")
        _pose(model, root.pose)
        names = {n.name for n in nodes}
        for node in nodes:
            self._link(model, node, root, with_inertial=not static)
        for node in nodes:
            joint = self.joint_of.get(node.name)
            if node is root:
                if joint is not None:
                    self._joint(model, joint, names)
                elif not static and root.static:
                    # The root stays put while its descendants move: weld it to the world.
                    self._fixed(model, self._fresh(f"{root.name}_world"), "world", root.name)
            elif joint is not None:
                if joint.parent != node.parent:
                    raise WorldgenError(
                        f"joint {joint.name!r} joins {joint.child!r} to {joint.parent!r}, "
                        f"but that node's parent is {node.parent!r}")
                self._joint(model, joint, names)
            else:
                self._fixed(model, self._fresh(f"{node.name}_fixed"), node.parent, node.name)

    def _fresh(self, base: str) -> str:
        name, k = base, 1
        while name in self.taken:
            name, k = f"{base}_{k}", k + 1
        self.taken.add(name)
        return name

    def _link(self, model, node: Node, root: Node, with_inertial: bool) -> None:
        link = _el(model, "link", name=node.name)
        if node is not root:
            if self.frames:
                _pose(link, node.pose, relative_to=node.parent)
            else:
                in_model = np.linalg.inv(self.scene.world_matrix(root.name)) @ self.scene.world_matrix(node.name)
                _pose(link, matrix_to_pose(in_model))
        if with_inertial:
            _inertial(link, node)
        if node.shape is None:
            return
        geometry = _geometry(node.shape)
        if node.collision:
            collision = _el(link, "collision", name="collision")
            collision.append(_clone(geometry))
            collision.append(_clone(self._surface(node.material.friction)))
        visual = _el(link, "visual", name="visual")
        visual.append(geometry)
        visual.append(_clone(self._material(node.material.rgba)))
        if node.material.rgba[3] < 1.0:
            _el(visual, "transparency", fmt(1.0 - node.material.rgba[3]))

    # Surfaces and colours repeat across many nodes: build each once, copy it after.
    def _surface(self, friction: float):
        if friction not in self.surfaces:
            surface = etree.Element("surface")
            ode = _el(_el(surface, "friction"), "ode")
            _el(ode, "mu", fmt(friction))
            _el(ode, "mu2", fmt(friction))
            self.surfaces[friction] = surface
        return self.surfaces[friction]

    def _material(self, rgba: tuple):
        if rgba not in self.materials:
            material = etree.Element("material")
            text = fmt_seq(rgba)
            _el(material, "ambient", text)
            _el(material, "diffuse", text)
            self.materials[rgba] = material
        return self.materials[rgba]

    def _joint(self, model, joint: Joint, names: set[str]) -> None:
        if joint.parent != "world" and joint.parent not in names:
            raise WorldgenError(
                f"joint {joint.name!r}: parent {joint.parent!r} is not in the model of {joint.child!r}; "
                "SDF joints stay inside one model")
        if joint.kind == "fixed":
            element = self._fixed(model, joint.name, joint.parent, joint.child)
            if not _is_identity(joint.pose):
                element.insert(0, _pose_element(joint.pose))
            return
        element = _el(model, "joint", name=joint.name, type="revolute")
        if not _is_identity(joint.pose):
            _pose(element, joint.pose)
        _el(element, "parent", joint.parent)
        _el(element, "child", joint.child)
        axis = _el(element, "axis")
        _el(axis, "xyz", fmt_seq(joint.axis))
        _el(_el(axis, "dynamics"), "damping", fmt(joint.damping))
        limit = _el(axis, "limit")
        # The written poses are the joint's zero: measure the limits from the initial angle.
        _el(limit, "lower", fmt(joint.limits[0] - joint.initial))
        _el(limit, "upper", fmt(joint.limits[1] - joint.initial))
        _el(limit, "effort", fmt(joint.effort))
        _el(limit, "velocity", fmt(joint.velocity))

    @staticmethod
    def _fixed(model, name: str, parent: str, child: str):
        element = _el(model, "joint", name=name, type="fixed")
        _el(element, "parent", parent)
        _el(element, "child", child)
        return element


def _is_identity(pose: Pose) -> bool:
    return all(fmt(v) == "0" for v in pose.as_list())


def _pose_element(pose: Pose, relative_to: Optional[str] = None):
    element = etree.Element("pose")
    if relative_to is not None:
        element.set("relative_to", relative_to)
    element.text = fmt_seq(pose.as_list())
    return element


def _pose(parent, pose: Pose, relative_to: Optional[str] = None) -> None:
    parent.append(_pose_element(pose, relative_to))


def _inertial(link, node: Node) -> None:
    inertial = _el(link, "inertial")
    if isinstance(node.shape, Mesh):
        # The moments are those of the mesh's bounding box, about the box's centre.
        v = node.shape.scaled_vertices()
        centre = (v.min(axis=0) + v.max(axis=0)) / 2.0
        if any(fmt(c) != "0" for c in centre):
            _pose(inertial, Pose(*centre))
    _el(inertial, "mass", fmt(node.mass))
    ixx, iyy, izz = (max(i, MIN_MOMENT) for i in node.inertia)
    inertia = _el(inertial, "inertia")
    for tag, value in (("ixx", ixx), ("ixy", 0.0), ("ixz", 0.0), ("iyy", iyy), ("iyz", 0.0), ("izz", izz)):
        _el(inertia, tag, fmt(value))


def _clone(element: etree._Element) -> etree._Element:
    """A deep copy of a small cached subtree (lxml's own copy, without the copy module's dispatch)."""
    return element.__deepcopy__(None)


def _el(parent, tag: str, text: Optional[str] = None, **attrs) -> etree._Element:
    """``sub`` without its per-attribute loop: this exporter's hot path."""
    element = etree.SubElement(parent, tag, attrs) if attrs else etree.SubElement(parent, tag)
    if text is not None:
        element.text = text
    return element


def _geometry(shape) -> etree._Element:
    """A detached ``<geometry>`` element for ``shape`` (SDF sizes: full extents, radius, length)."""
    geometry = etree.Element("geometry")
    if isinstance(shape, Box):
        _el(_el(geometry, "box"), "size", fmt_seq(shape.size))
    elif isinstance(shape, Cylinder):
        cylinder = _el(geometry, "cylinder")
        _el(cylinder, "radius", fmt(shape.radius))
        _el(cylinder, "length", fmt(shape.length))
    elif isinstance(shape, Sphere):
        _el(_el(geometry, "sphere"), "radius", fmt(shape.radius))
    elif isinstance(shape, Mesh):
        mesh = _el(geometry, "mesh")
        _el(mesh, "uri", shape.uri)
        _el(mesh, "scale", fmt_seq(shape.scale))
    else:
        raise WorldgenError(f"the SDF exporter has no geometry for shape {shape!r}")
    return geometry
