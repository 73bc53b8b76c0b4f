"""Occupancy map: read back as the ROS 2 map server would, and compared with the geometry."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
import yaml
from support.scenes import showcase_scene

import worldgen
from worldgen.errors import ParameterError
from worldgen.groundtruth import occupancy
from worldgen.scene import Box, Node, Pose, Scene


def read_pgm(data: bytes) -> np.ndarray:
    """A binary (P5) PGM, parsed here: header tokens separated by whitespace, then raw bytes."""
    assert data[:2] == b"P5"
    tokens, pos = [], 2
    while len(tokens) < 3:
        while data[pos:pos + 1].isspace():
            pos += 1
        start = pos
        while not data[pos:pos + 1].isspace():
            pos += 1
        tokens.append(int(data[start:pos]))
    width, height, maxval = tokens
    assert maxval == 255
    pixels = np.frombuffer(data[pos + 1:], dtype=np.uint8)
    assert pixels.size == width * height
    return pixels.reshape(height, width)


TOUCH = 1e-9  # meeting a cell by less than this is a touch (worldgen's documented tolerance)


def cell_boxes(meta: dict, image: np.ndarray):
    """shapely squares of every pixel shrunk by TOUCH, in image order (row 0 = top), and their centres."""
    h = meta["resolution"]
    ox, oy, _ = meta["origin"]
    rows, cols = image.shape
    j, i = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
    y0 = oy + (rows - 1 - j) * h  # image row 0 is the top of the map
    x0 = ox + i * h
    return (shapely.box(x0 + TOUCH, y0 + TOUCH, x0 + h - TOUCH, y0 + h - TOUCH),
            np.stack([x0 + h / 2, y0 + h / 2], axis=-1))


def reference_sections(scene: Scene, z: float):
    """Exact sections of yawed boxes and upright cylinders at z, as shapely shapes plus discs."""
    polys, discs = [], []
    for node in scene.nodes:
        if node.shape is None or not node.collision:
            continue
        p, s = node.pose, node.shape
        half = s.size[2] / 2 if s.kind == "box" else s.length / 2
        if abs(z - p.z) > half:
            continue
        if s.kind == "box":
            c, n = math.cos(p.yaw), math.sin(p.yaw)
            hx, hy = s.size[0] / 2, s.size[1] / 2
            polys.append(shapely.Polygon([(p.x + c * u - n * v, p.y + n * u + c * v)
                                          for u, v in ((-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy))]))
        else:
            discs.append((p.x, p.y, s.radius))
    return polys, discs


def reference_occupied(meta, image, scene, z):
    """A cell is occupied when its square, shrunk by TOUCH, meets a section."""
    boxes, centres = cell_boxes(meta, image)
    h = meta["resolution"]
    occ = np.zeros(image.shape, dtype=bool)
    polys, discs = reference_sections(scene, z)
    for poly in polys:
        occ |= shapely.intersects(boxes, poly)
    for x, y, r in discs:
        # Distance from the disc's centre to the square: the clamp of the centre into the square.
        half = h / 2 - TOUCH
        dx = np.clip(x, centres[..., 0] - half, centres[..., 0] + half) - x
        dy = np.clip(y, centres[..., 1] - half, centres[..., 1] + half) - y
        occ |= np.hypot(dx, dy) <= r
    return occ


@pytest.mark.parametrize("seed", range(4))
def test_written_map_reads_back_as_the_geometry(tmp_path, seed):
    world = worldgen.generate("cluttered", seed=seed, size=[8, 6], n_obstacles=20, map_resolution=0.04 + 0.01 * seed,
                              map_height=0.2 + 0.3 * seed, obstacle_height=[0.3, 1.2])
    folder = world.write(tmp_path)
    meta = world.metadata["occupancy"]
    assert (meta["image"], meta["yaml"]) == ("map.pgm", "map.yaml")
    files = world.metadata["files"]
    assert files["map_pgm"]["path"] == "map.pgm" and files["map_yaml"]["path"] == "map.yaml"
    spec = yaml.safe_load((folder / "map.yaml").read_text())
    assert spec == {"image": "map.pgm", "mode": "trinary", "resolution": meta["resolution"],
                    "origin": meta["origin"], "negate": 0, "occupied_thresh": 0.65, "free_thresh": 0.25}
    image = read_pgm((folder / "map.pgm").read_bytes())
    assert set(np.unique(image)) <= {0, 254}
    # The map covers the floor slab (the room and its walls) in whole cells from its lower-left corner.
    floor = world.scene.aabb("floor")
    assert meta["origin"][:2] == pytest.approx(floor[0, :2].tolist(), abs=1e-6)
    h = meta["resolution"]
    assert image.shape == (math.ceil(round((floor[1, 1] - floor[0, 1]) / h, 6)), math.ceil(round((floor[1, 0] - floor[0, 0]) / h, 6)))
    expected = reference_occupied(meta, image, world.scene, world.params["map_height"])
    np.testing.assert_array_equal(image == 0, expected)
    # nav2's reading: p = (255 - v) / 255 with negate 0; black is occupied, white is free.
    p = (255 - image.astype(float)) / 255
    assert np.all((p > 0.65) == (image == 0)) and np.all((p < 0.25) == (image == 254))


def test_walls_thinner_than_a_cell_still_close_the_map():
    floor = Node("floor", "floor", Box((4.0, 4.0, 0.1)), Pose(0, 0, -0.05))
    thin = Node("thin", "wall", Box((0.01, 3.0, 1.0)), Pose(0.512, 0.0, 0.5))
    diagonal = Node("diag", "wall", Box((0.005, 2.0, 1.0)), Pose(-1.0, 0.0, 0.5, 0, 0, 0.7))
    scene = Scene((floor, thin, diagonal), bounds=((-2, -2), (2, 2)))
    grid = occupancy.build(scene, 0.1, 0.05)
    occ = grid.occupied
    # Every row the thin wall spans has exactly one black cell in its column; no gap anywhere.
    rows = slice(int(round((-1.5 + 2) / 0.05)), int(round((1.5 + 2) / 0.05)))
    col = int((0.512 + 2) // 0.05)
    assert occ[rows, col].all() and not occ[rows, col - 1].any() and not occ[rows, col + 1].any()
    # The turned hairline wall: 8-connected, no free cell lets a path through (each row and column it
    # crosses has a black cell).
    d = occ.copy()
    d[:, col] = False
    ys, xs = np.nonzero(d)
    assert len(ys) and np.all(np.diff(np.unique(ys)) == 1) and np.all(np.diff(np.unique(xs)) == 1)
    # The same map again: the same bytes.
    assert grid.pgm() == occupancy.build(scene, 0.1, 0.05).pgm()


def _inside_and_distance(scene, pts3):
    """(inside, distance) of points to the union of the solids, in each solid's frame."""
    inside = np.zeros(len(pts3), dtype=bool)
    dist = np.full(len(pts3), np.inf)
    for node in scene.nodes:
        if node.shape is None or not node.collision:
            continue
        m = scene.world_matrix(node.name)
        local = (pts3 - m[:3, 3]) @ m[:3, :3]
        s = node.shape
        if s.kind == "box":
            q = np.abs(local) - np.asarray(s.size) / 2
            d = np.linalg.norm(np.maximum(q, 0), axis=1)
            ins = (q <= 0).all(axis=1)
        elif s.kind == "cylinder":
            radial = np.hypot(local[:, 0], local[:, 1]) - s.radius
            axial = np.abs(local[:, 2]) - s.length / 2
            d = np.hypot(np.maximum(radial, 0), np.maximum(axial, 0)) + 0.002  # the map's prism is a hair wider
            ins = (radial <= 0) & (axial <= 0)
        elif s.kind == "sphere":
            d = np.linalg.norm(local, axis=1) - s.radius
            ins = d <= 0
        else:
            # The test meshes are convex and face outward: inside = behind every face plane; the
            # largest plane distance is a lower bound of the distance, enough to prove a cell far.
            tri = s.scaled_vertices()[s.faces]
            normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
            normal /= np.linalg.norm(normal, axis=1, keepdims=True)
            plane = (local[:, None, :] - tri[None, :, 0]) @ np.eye(3)
            signed = np.einsum("pfk,fk->pf", plane, normal).max(axis=1)
            ins = signed <= 0
            d = np.maximum(signed, 0.0)
        inside |= ins
        dist = np.minimum(dist, np.where(ins, 0.0, d))
    return inside, dist


@pytest.mark.parametrize("z", [0.05, 0.2, 0.45, 0.9])
def test_tilted_shapes_spheres_and_meshes(z):
    scene = showcase_scene()
    h = 0.05
    grid = occupancy.build(scene, z, h)
    rows, cols = grid.occupied.shape
    j, i = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
    centres = np.stack([grid.origin[0] + (i + 0.5) * h, grid.origin[1] + (j + 0.5) * h, np.full(i.shape, z)], -1)
    inside, dist = _inside_and_distance(scene, centres.reshape(-1, 3))
    occ = grid.occupied.reshape(-1)
    assert occ[inside].all()  # a cell whose centre is inside a shape is black
    far = dist > h * math.sqrt(2) / 2 + 1e-9  # no point of the cell can reach a shape
    assert not occ[far].any()
    assert occ.sum() > inside.sum()  # the cells the boundaries cross count too


def test_map_parameters_are_checked():
    with pytest.raises(ParameterError, match=r"parameter 'map_resolution' must be in \[0.005, 10\], got 0.001"):
        worldgen.generate("cluttered", seed=0, map_resolution=0.001)
    scene = Scene((Node("floor", "floor", Box((500.0, 500.0, 0.1)), Pose(0, 0, -0.05)),), bounds=((-250, -250), (250, 250)))
    with pytest.raises(ParameterError, match=r"parameter 'map_resolution' must be at least 0.1000 m for this 500 x 500 m floor"):
        occupancy.build(scene, 0.1, 0.05)
