"""The pieces of a USD layer that the USD writer (:mod:`worldgen.export.usd`) puts together: prim and
property specs, rotations as quaternions, one shape as a UsdGeom prim, and the optional ``pxr`` import.

The layer is authored through ``pxr.Sdf`` (specs straight into one layer) rather than through
``Usd.Stage`` and the schema classes: the same text comes out, at a third of the cost (a stage
re-composes after every edit; an ``Sdf.ChangeBlock`` batches the notices). Every number is rounded
as :func:`worldgen.floats.round_float` rounds (quaternions to 12 decimals, see below) before it is
written, so the text does not depend on a float's last bits; ``Sdf`` writes each double in its
shortest round-tripping form.
"""

from __future__ import annotations

import math
from typing import Any, Iterable, Optional, Sequence

import numpy as np

from worldgen.errors import WorldgenError, optional_available, require_optional
from worldgen.files import USDA_NAME
from worldgen.floats import DECIMALS, round_float
from worldgen.scene.shapes import Box, Cylinder, Mesh, Shape, Sphere

__all__ = ["SHAPE_PRIM", "INSTALL_HINT", "require_pxr", "usd_available", "Specs", "quaternion", "matrix_quaternion"]

#: The prim under a node's, mover's or person's Xform that holds its shape.
SHAPE_PRIM = "shape"
#: What to install for USD (the ``usd`` extra of worldgen's pyproject.toml: Pixar's usd-core wheels).
INSTALL_HINT = "pip install 'worldgen[usd]'"  # what require_optional's message says, for docs and callers


def usd_available() -> bool:
    """True when ``pxr`` (usd-core) can be imported; nothing is imported by asking."""
    return optional_available("pxr")


def require_pxr():
    """The ``pxr`` package with Sdf, Gf and Vt loaded, or MissingDependencyError naming the ``usd`` extra."""
    needs = "the usd format needs usd-core (Pixar's pxr)"
    for module in ("pxr.Sdf", "pxr.Gf", "pxr.Vt"):
        require_optional(module, "usd", needs)
    return require_optional("pxr", "usd", needs)


def quaternion(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """(w, x, y, z) of R = Rz(yaw) Ry(pitch) Rx(roll) (worldgen's and SDF's fixed-axis roll-pitch-yaw)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy)


def matrix_quaternion(r: np.ndarray) -> tuple[float, float, float, float]:
    """(w, x, y, z), w >= 0, of the (3, 3) rotation ``r`` (Shepperd's method: the largest diagonal term first)."""
    trace = r[0, 0] + r[1, 1] + r[2, 2]
    if trace > max(r[0, 0], r[1, 1], r[2, 2]):
        s = 2 * math.sqrt(1 + trace)
        q = (s / 4, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s)
    elif r[0, 0] >= r[1, 1] and r[0, 0] >= r[2, 2]:
        s = 2 * math.sqrt(1 + r[0, 0] - r[1, 1] - r[2, 2])
        q = ((r[2, 1] - r[1, 2]) / s, s / 4, (r[0, 1] + r[1, 0]) / s, (r[0, 2] + r[2, 0]) / s)
    elif r[1, 1] >= r[2, 2]:
        s = 2 * math.sqrt(1 + r[1, 1] - r[0, 0] - r[2, 2])
        q = ((r[0, 2] - r[2, 0]) / s, (r[0, 1] + r[1, 0]) / s, s / 4, (r[1, 2] + r[2, 1]) / s)
    else:
        s = 2 * math.sqrt(1 + r[2, 2] - r[0, 0] - r[1, 1])
        q = ((r[1, 0] - r[0, 1]) / s, (r[0, 2] + r[2, 0]) / s, (r[1, 2] + r[2, 1]) / s, s / 4)
    return q if q[0] >= 0 else (-q[0], -q[1], -q[2], -q[3])


def _r(values: Iterable[float]) -> list[float]:
    # round_float's rounding (a snapped -0.0 made 0.0 by + 0.0), without its finiteness test: a scene's
    # numbers are finite by construction, and this runs for every number of every prim.
    return [round(float(v), DECIMALS) + 0.0 for v in values]


#: Decimals of a written quaternion. USD turns an ``orient`` into a matrix through its angle, 2 acos(w),
#: which magnifies an error in w by 1 / sin(angle / 2): at 6 decimals a yaw of 0.125 rad came out
#: 1.6e-5 rad off (found by the hinge test), a yaw of 0.01 rad 1e-4 rad (1 mm at the end of a 20 m
#: wall). At 12 decimals the text still does not depend on a float's last bits.
QUATERNION_DECIMALS = 12


def _rq(values: Iterable[float]) -> list[float]:
    return [round(float(v), QUATERNION_DECIMALS) + 0.0 for v in values]  # + 0.0: no negative zero


class Specs:
    """Writes specs into one ``Sdf.Layer``: prims, attributes, relationships, transforms and shapes."""

    def __init__(self, pxr):
        self.Sdf, self.Gf, self.Vt = pxr.Sdf, pxr.Gf, pxr.Vt
        self.T = pxr.Sdf.ValueTypeNames
        self.layer = pxr.Sdf.Layer.CreateAnonymous(USDA_NAME)
        # Box prims that differ only in their extents are copied from one written here (see shape()).
        self._templates = pxr.Sdf.Layer.CreateAnonymous("templates.usda")
        self._template_paths: dict[tuple, Any] = {}

    def prim(self, parent, name: str, type_name: str, api: Sequence[str] = ()):
        """A ``def`` prim under ``parent`` (a PrimSpec, or None for the layer's root) with API schemas applied."""
        Sdf = self.Sdf
        spec = Sdf.PrimSpec(self.layer if parent is None else parent, name, Sdf.SpecifierDef, type_name)
        if api:
            spec.SetInfo("apiSchemas", Sdf.TokenListOp.Create(prependedItems=list(api)))
        return spec

    def attr(self, prim, name: str, type_name: str, value: Any, uniform: bool = False):
        Sdf = self.Sdf
        spec = Sdf.AttributeSpec(prim, name, getattr(self.T, type_name),
                                 Sdf.VariabilityUniform if uniform else Sdf.VariabilityVarying)
        if value is not None:
            spec.default = value
        return spec

    def rel(self, prim, name: str, target: str) -> None:
        spec = self.Sdf.RelationshipSpec(prim, name, custom=False)
        spec.targetPathList.explicitItems = [self.Sdf.Path(target)]

    def vec3(self, values, type_name: str = "Double3"):
        gf = self.Gf.Vec3d if type_name[0] == "D" else self.Gf.Vec3f
        return gf(*_r(values))

    def quat(self, wxyz, double: bool = True):
        w, x, y, z = _rq(wxyz)
        return (self.Gf.Quatd if double else self.Gf.Quatf)(w, x, y, z)

    def transform(self, prim, position, wxyz) -> None:
        """``translate`` then ``orient``: the ops (and order) Isaac Sim expects of an Xform."""
        self.attr(prim, "xformOp:translate", "Double3", self.vec3(position))
        self.attr(prim, "xformOp:orient", "Quatd", self.quat(wxyz))
        self.attr(prim, "xformOpOrder", "TokenArray", ["xformOp:translate", "xformOp:orient"], uniform=True)

    def shape(self, parent, shape, rgba, material: Optional[str], rigid: bool, name: str = SHAPE_PRIM):
        """The gprim of ``shape`` under ``parent``: a unit Cube scaled to a box's extents, a Cylinder
        along z, a Sphere, or a Mesh; a collider bound to the physics ``material`` path unless that is None.

        A box or cylinder is copied (``Sdf.CopySpec``, one call into usd-core) from a template with the
        same colour, material and body, then given its sizes: the same specs as writing it field by
        field, for about half the cost (boxes and cylinders are most of a world).
        """
        template: Shape
        if isinstance(shape, Box):
            key, template = ("box", tuple(rgba), material, rigid, name), Box((1.0, 1.0, 1.0))
        elif isinstance(shape, Cylinder):
            key, template = ("cylinder", tuple(rgba), material, rigid, name), Cylinder(1.0, 1.0)
        else:
            return self._shape(parent, shape, rgba, material, rigid, name)
        source = self._template_paths.get(key)
        if source is None:
            holder = self.Sdf.PrimSpec(self._templates, f"t{len(self._template_paths)}", self.Sdf.SpecifierDef, "Xform")
            source = self._template_paths[key] = self._shape(holder, template, rgba, material, rigid, name).path
        target = parent.path.AppendChild(name)
        self.Sdf.CopySpec(self._templates, source, self.layer, target)
        attribute = self.layer.GetAttributeAtPath
        if isinstance(shape, Box):
            attribute(target.AppendProperty("xformOp:scale")).default = self.vec3(shape.size)
        else:
            r, h = shape.radius, shape.length
            attribute(target.AppendProperty("radius")).default = round_float(r)
            attribute(target.AppendProperty("height")).default = round_float(h)
            attribute(target.AppendProperty("extent")).default = self._extent((r, r, h / 2))
        return self.layer.GetPrimAtPath(target)

    def _extent(self, half):
        return self.Vt.Vec3fArray([self.vec3([-h for h in half], "Float3"), self.vec3(half, "Float3")])

    def _shape(self, parent, shape, rgba, material: Optional[str], rigid: bool, name: str):
        api = [] if material is None else ["PhysicsCollisionAPI", "MaterialBindingAPI"]
        if isinstance(shape, Box):
            prim = self.prim(parent, name, "Cube", api)
            self.attr(prim, "size", "Double", 1.0)
            self.transform_scale(prim, shape.size)
            half = (0.5, 0.5, 0.5)
        elif isinstance(shape, Cylinder):
            prim = self.prim(parent, name, "Cylinder", api)
            self.attr(prim, "radius", "Double", round_float(shape.radius))
            self.attr(prim, "height", "Double", round_float(shape.length))
            self.attr(prim, "axis", "Token", "Z", uniform=True)
            half = (shape.radius, shape.radius, shape.length / 2)
        elif isinstance(shape, Sphere):
            prim = self.prim(parent, name, "Sphere", api)
            self.attr(prim, "radius", "Double", round_float(shape.radius))
            half = (shape.radius,) * 3
        elif isinstance(shape, Mesh):
            prim = self._mesh(parent, name, shape, api + (["PhysicsMeshCollisionAPI"] if api else []), rigid)
            half = None
        else:
            raise WorldgenError(f"the USD exporter has no geometry for shape {shape!r}")
        if half is not None:
            self.attr(prim, "extent", "Float3Array", self._extent(half))
        self.attr(prim, "primvars:displayColor", "Color3fArray", self.Vt.Vec3fArray([self.vec3(rgba[:3], "Float3")]))
        if rgba[3] < 1.0:
            self.attr(prim, "primvars:displayOpacity", "FloatArray", self.Vt.FloatArray([round_float(rgba[3])]))
        if material is not None:
            self.rel(prim, "material:binding:physics", material)
        return prim

    def transform_scale(self, prim, scale) -> None:
        self.attr(prim, "xformOp:scale", "Double3", self.vec3(scale))
        self.attr(prim, "xformOpOrder", "TokenArray", ["xformOp:scale"], uniform=True)

    def _mesh(self, parent, name: str, mesh: Mesh, api: list, rigid: bool):
        prim = self.prim(parent, name, "Mesh", api)
        points = np.round(mesh.vertices, DECIMALS) + 0.0  # + 0.0: no negative zero in the text
        self.attr(prim, "points", "Point3fArray", self.Vt.Vec3fArray.FromNumpy(points.astype(np.float32)))
        self.attr(prim, "faceVertexCounts", "IntArray", self.Vt.IntArray([3] * len(mesh.faces)))
        self.attr(prim, "faceVertexIndices", "IntArray", self.Vt.IntArray.FromNumpy(mesh.faces.reshape(-1).astype(np.int32)))
        self.attr(prim, "subdivisionScheme", "Token", "none", uniform=True)
        lo, hi = points.min(axis=0), points.max(axis=0)
        self.attr(prim, "extent", "Float3Array", self.Vt.Vec3fArray([self.vec3(lo, "Float3"), self.vec3(hi, "Float3")]))
        if api:
            # A static collider may be the triangle mesh itself; PhysX simulates a moving one only as a convex hull.
            self.attr(prim, "physics:approximation", "Token", "convexHull" if rigid else "none", uniform=True)
        if any(s != 1.0 for s in mesh.scale):
            self.transform_scale(prim, mesh.scale)
        return prim
