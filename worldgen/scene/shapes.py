"""Collision and visual shapes, with SDF's size conventions (full extents)."""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field
from typing import Optional, Union

import numpy as np

from worldgen.errors import SceneError
from worldgen.floats import round_float

__all__ = ["Box", "Cylinder", "Sphere", "Mesh", "Shape", "unit_inertia", "canonical_shape"]


def _positive(kind: str, name: str, value: float) -> float:
    value = float(value)
    if not (math.isfinite(value) and value > 0):
        raise SceneError(f"{kind} {name} must be a positive finite number, got {value!r}")
    return value


@dataclass(frozen=True)
class Box:
    """A box centred on its frame; ``size`` is the full extents (sx, sy, sz) in metres."""

    size: tuple[float, float, float]
    kind: str = field(default="box", init=False)

    def __post_init__(self):
        if len(self.size) != 3:
            raise SceneError(f"box size needs 3 values, got {self.size!r}")
        object.__setattr__(self, "size", tuple(_positive("box", "size", v) for v in self.size))

    def local_corners(self) -> np.ndarray:
        """(8, 3) float corners in the shape's frame."""
        h = np.asarray(self.size) / 2.0
        signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
        return signs * h

    def volume(self) -> float:
        sx, sy, sz = self.size
        return sx * sy * sz

    def describe(self) -> dict:
        return {"type": "box", "size": list(self.size)}


@dataclass(frozen=True)
class Cylinder:
    """A cylinder along its frame's z axis, centred on the frame."""

    radius: float
    length: float
    kind: str = field(default="cylinder", init=False)

    def __post_init__(self):
        object.__setattr__(self, "radius", _positive("cylinder", "radius", self.radius))
        object.__setattr__(self, "length", _positive("cylinder", "length", self.length))

    def local_corners(self) -> np.ndarray:
        """(8, 3) corners of the cylinder's bounding box in its frame."""
        return Box((2 * self.radius, 2 * self.radius, self.length)).local_corners()

    def volume(self) -> float:
        return math.pi * self.radius**2 * self.length

    def describe(self) -> dict:
        return {"type": "cylinder", "radius": self.radius, "length": self.length}


@dataclass(frozen=True)
class Sphere:
    """A sphere centred on its frame."""

    radius: float
    kind: str = field(default="sphere", init=False)

    def __post_init__(self):
        object.__setattr__(self, "radius", _positive("sphere", "radius", self.radius))

    def local_corners(self) -> np.ndarray:
        d = 2 * self.radius
        return Box((d, d, d)).local_corners()

    def volume(self) -> float:
        return 4.0 / 3.0 * math.pi * self.radius**3

    def describe(self) -> dict:
        return {"type": "sphere", "radius": self.radius}


@dataclass(frozen=True, eq=False)
class Mesh:
    """A triangle mesh. ``uri`` is where exporters write it, relative to the world folder.

    ``vertices`` is (n, 3) float and ``faces`` (m, 3) int, both stored read-only;
    ``scale`` multiplies the vertices, as SDF's ``<scale>`` does.
    """

    uri: str
    vertices: np.ndarray
    faces: np.ndarray
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    kind: str = field(default="mesh", init=False)

    def __post_init__(self):
        v = np.array(self.vertices, dtype=float).reshape(-1, 3)
        f = np.array(self.faces, dtype=np.int64).reshape(-1, 3)
        if len(v) < 4 or len(f) < 4:
            raise SceneError("mesh needs at least 4 vertices and 4 faces")
        if f.min() < 0 or f.max() >= len(v):
            raise SceneError("mesh faces index missing vertices")
        if not np.all(np.isfinite(v)):
            raise SceneError("mesh vertices must be finite")
        v.flags.writeable = False
        f.flags.writeable = False
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "faces", f)
        object.__setattr__(self, "scale", tuple(_positive("mesh", "scale", s) for s in self.scale))
        if ".." in self.uri.split("/") or self.uri.startswith("/"):
            raise SceneError(f"mesh uri must stay inside the world folder, got {self.uri!r}")

    @classmethod
    def from_trimesh(cls, uri: str, mesh, scale=(1.0, 1.0, 1.0)) -> "Mesh":
        return cls(uri, mesh.vertices, mesh.faces, scale)

    def to_trimesh(self):
        import trimesh

        return trimesh.Trimesh(self.scaled_vertices(), self.faces, process=False)

    def scaled_vertices(self) -> np.ndarray:
        """(n, 3) float vertices with ``scale`` applied."""
        return self.vertices * np.asarray(self.scale)

    def local_corners(self) -> np.ndarray:
        v = self.scaled_vertices()
        lo, hi = v.min(axis=0), v.max(axis=0)
        return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])

    def volume(self) -> float:
        return abs(float(self.to_trimesh().volume))

    def describe(self) -> dict:
        return {"type": "mesh", "uri": self.uri, "scale": list(self.scale)}

    def __eq__(self, other):
        return (
            isinstance(other, Mesh)
            and self.uri == other.uri
            and self.scale == other.scale
            and np.array_equal(self.vertices, other.vertices)
            and np.array_equal(self.faces, other.faces)
        )

    def __hash__(self):
        return hash((self.uri, self.scale, self.vertices.tobytes(), self.faces.tobytes()))

    def __repr__(self):
        return f"Mesh(uri={self.uri!r}, vertices={len(self.vertices)}, faces={len(self.faces)}, scale={self.scale})"


Shape = Union[Box, Cylinder, Sphere, Mesh]


def unit_inertia(shape: Shape) -> tuple[float, float, float]:
    """Principal moments (ixx, iyy, izz) of a solid ``shape`` of mass 1 kg about its centre.

    For a mesh, the moments of its bounding box: a conservative, always valid stand-in.
    """
    if isinstance(shape, Box) or isinstance(shape, Mesh):
        sx, sy, sz = shape.size if isinstance(shape, Box) else tuple(np.ptp(shape.scaled_vertices(), axis=0))
        return ((sy * sy + sz * sz) / 12.0, (sx * sx + sz * sz) / 12.0, (sx * sx + sy * sy) / 12.0)
    if isinstance(shape, Cylinder):
        r, h = shape.radius, shape.length
        side = (3 * r * r + h * h) / 12.0
        return (side, side, r * r / 2.0)
    if isinstance(shape, Sphere):
        i = 0.4 * shape.radius**2
        return (i, i, i)
    raise SceneError(f"unknown shape {shape!r}")


def canonical_shape(shape: Optional[Shape]) -> Optional[dict]:
    """The shape's part of a scene's canonical description (what its content hash is taken of): its
    :meth:`describe` with floats rounded, and for a mesh the SHA-256 of its rounded geometry."""
    if shape is None:
        return None
    d = {k: ([round_float(x) for x in v] if isinstance(v, (list, tuple)) else (round_float(v) if isinstance(v, float) else v))
         for k, v in shape.describe().items()}
    if isinstance(shape, Mesh):
        d["geometry_sha256"] = hashlib.sha256(
            np.round(shape.vertices, 6).astype("<f8").tobytes() + shape.faces.astype("<i8").tobytes()
        ).hexdigest()
    return d
