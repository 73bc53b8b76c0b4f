"""BARN's difficulty metrics, recomputed on the written map.pgm, against world.json's ``metrics``.

BARN (Perille et al., SSRR 2020; its generator's ``difficulty_quant.py`` as of commit 947fe6f,
2020-10-27) defines its five metrics on an occupancy grid at the cells of the path. They are
re-implemented here from that definition, independently of worldgen (the map is read from the PGM
and YAML files, the path from world.json): closest-wall distance (Euclidean, in cells, to the nearest
occupied cell), average visibility (8 grid directions, diagonal steps weighing sqrt 2, a ray leaving
the map counted up to the edge), dispersion (wall / no wall alternations over BARN's 16 step
directions within a radius of steps, in-between directions counting 2 a step), characteristic
dimension (the shortest free line through the cell over 4 axes) and tortuosity (arc / chord).

worldgen computes its figures exactly in metres (docs/metrics.md), so they agree with BARN's only
within the tolerances below, each stated with the reason for it. The map and the metrics must
describe the same scene (doors at their open limit, as planning): a door world whose map showed the
leaves where they start would miss the closest-wall tolerance by about 0.1 m.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy import ndimage

import worldgen

#: Closest-wall distance (m): BARN measures between cell centres, worldgen to the exact boundary:
#: they differ by up to one cell (map_resolution, 0.05 m by default).
CLOSEST_TOL = 0.05
#: Tortuosity (relative): the waypoints' cells instead of the waypoints move each end by half a cell.
TORTUOSITY_REL = 0.02
#: Average visibility (relative): BARN casts 8 grid directions, worldgen 16 exact ones.
VISIBILITY_REL = 0.25
#: Characteristic dimension (relative): BARN takes the shortest of 4 grid axes, worldgen of 8 exact lines.
CHARDIM_REL = 0.25
#: Dispersion (BARN / worldgen): BARN's rays reach at least as far as worldgen's (the radius counts
#: steps, and diagonal steps are sqrt 2 long) and its 16 directions are unevenly spaced, so it counts
#: more alternations: measured 1.1x to 1.5x on these worlds.
DISPERSION_RATIO = (0.9, 1.6)

# -- reading the written files --------------------------------------------------------------

def read_pgm(path: Path) -> np.ndarray:
    """(rows, cols) uint8 of a binary PGM (P5, maxval < 256, no comments: what the map server reads)."""
    magic, width, height, maxval, pixels = path.read_bytes().split(maxsplit=4)
    assert magic == b"P5" and int(maxval) < 256
    return np.frombuffer(pixels[: int(width) * int(height)], dtype=np.uint8).reshape(int(height), int(width))


def read_map(folder: Path):
    spec = yaml.safe_load((folder / "map.yaml").read_text())
    image = read_pgm(folder / spec["image"])
    occupied = image <= 255 * (1 - spec["occupied_thresh"])  # nav2's trinary reading, negate 0
    return occupied, spec["resolution"], spec["origin"][:2]


def cells_of(points: np.ndarray, occupied: np.ndarray, resolution: float, origin) -> list[tuple[int, int]]:
    """(row, col) of each point; row 0 is the image's top row (largest y)."""
    col = np.floor((points[:, 0] - origin[0]) / resolution).astype(int)
    row = occupied.shape[0] - 1 - np.floor((points[:, 1] - origin[1]) / resolution).astype(int)
    return list(zip(row.tolist(), col.tolist()))


def path_cells(waypoints, occupied, resolution, origin) -> list[tuple[int, int]]:
    """The cells the polyline passes through, in order (sampled at a quarter cell)."""
    w = np.asarray(waypoints, dtype=float)
    pts = [w[:1]]
    for a, b in zip(w[:-1], w[1:]):
        n = max(1, math.ceil(math.hypot(*(b - a)) / (resolution / 4)))
        pts.append(a + (b - a) * (np.arange(1, n + 1) / n)[:, None])
    out: list[tuple[int, int]] = []
    for cell in cells_of(np.vstack(pts), occupied, resolution, origin):
        if not out or cell != out[-1]:
            out.append(cell)
    return out


# -- BARN's definitions on a grid (cells) -----------------------------------------------------

DISPERSION_MOVES = ((0, 1), (1, 2), (1, 1), (2, 1), (1, 0), (2, -1), (1, -1), (1, -2),
                    (0, -1), (-2, -1), (-1, -1), (-1, -2), (-1, 0), (-2, 1), (-1, 1), (-1, 2))


class Grid:
    def __init__(self, occupied: np.ndarray):
        self.occ = occupied
        self.rows, self.cols = occupied.shape
        self.wall_distance = ndimage.distance_transform_edt(~occupied)  # to the nearest occupied cell centre

    def inside(self, r, c) -> bool:
        return 0 <= r < self.rows and 0 <= c < self.cols

    def free_run(self, r, c, dr, dc, include_start: bool) -> float:
        """Length (cells) walked from (r, c) along (dr, dc) over free cells, stopping at a wall or the edge."""
        length = 0.0
        if not include_start:
            r, c = r + dr, c + dc
        while self.inside(r, c) and not self.occ[r, c]:
            length += math.hypot(dr, dc)
            r, c = r + dr, c + dc
        return length

    def visibility(self, r, c) -> float:
        rays = [(dr, dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if (dr, dc) != (0, 0)]
        return sum(self.free_run(r, c, dr, dc, include_start=True) for dr, dc in rays) / len(rays)

    def dispersion(self, r, c, radius: int) -> int:
        walls = []
        for dr, dc in DISPERSION_MOVES:
            count, wall, rr, cc = 0, False, r, c
            while count < radius and not wall:
                rr, cc = rr + dr, cc + dc
                if not self.inside(rr, cc):
                    break
                wall = bool(self.occ[rr, cc])
                count += 2 if 2 in (abs(dr), abs(dc)) else 1
            walls.append(wall)
        return sum(walls[i] != walls[(i + 1) % len(walls)] for i in range(len(walls)))

    def characteristic_dimension(self, r, c) -> float:
        return min(self.free_run(r, c, dr, dc, False) + self.free_run(r, c, -dr, -dc, False)
                   for dr, dc in ((0, 1), (1, 1), (1, 0), (1, -1)))


def barn_metrics(folder: Path) -> tuple[dict, dict]:
    meta = json.loads((folder / "world.json").read_text())
    occupied, res, origin = read_map(folder)
    grid = Grid(occupied)
    inflation = meta["robot"]["radius"] + meta["robot"]["clearance"]
    radius = round(4 * inflation / res)  # worldgen's reach (4 inflation radii) in BARN's steps
    cells, tortuosity = [], []
    for task in meta["tasks"]:
        cells += path_cells(task["path"]["waypoints"], occupied, res, origin)
        ends = cells_of(np.asarray(task["path"]["waypoints"], dtype=float), occupied, res, origin)
        arc = sum(math.dist(a, b) for a, b in zip(ends[:-1], ends[1:]))
        tortuosity.append(arc / math.dist(ends[0], ends[-1]))
    assert not any(occupied[r, c] for r, c in cells), "the path runs through an occupied cell of map.pgm"
    return meta["metrics"], {
        "closest_obstacle_distance_mean": res * float(np.mean([grid.wall_distance[r, c] for r, c in cells])),
        "average_visibility": res * float(np.mean([grid.visibility(r, c) for r, c in cells])),
        "dispersion": float(np.mean([grid.dispersion(r, c, radius) for r, c in cells])),
        "characteristic_dimension": res * float(np.mean([grid.characteristic_dimension(r, c) for r, c in cells])),
        "tortuosity": float(np.mean(tortuosity)),
    }


WORLDS = [
    ("cluttered", 0, {}),
    ("cluttered", 1, {"size": [6.0, 6.0], "n_obstacles": 12}),
    ("corridor", 0, {"shape": "zigzag"}),
    ("door", 0, {"n_doors": 2, "state": "closed"}),
    ("door", 1, {"n_doors": 3, "state": "random"}),
    ("door", 140406, {"n_doors": 3, "state": "random", "hinge_side": "right", "door_width": 1.05, "size": [16.6, 3.7]}),
]


@pytest.mark.parametrize("generator,seed,params", WORLDS, ids=[f"{g}-{s}" for g, s, _ in WORLDS])
def test_barn_definitions_on_map_pgm_agree_with_world_json(tmp_path, generator, seed, params):
    folder = worldgen.generate(generator, seed=seed, **params).write(tmp_path, preview=False)
    ours, barn = barn_metrics(folder)
    assert abs(barn["closest_obstacle_distance_mean"] - ours["closest_obstacle_distance_mean"]) <= CLOSEST_TOL
    assert barn["tortuosity"] == pytest.approx(ours["tortuosity"], rel=TORTUOSITY_REL)
    assert barn["average_visibility"] == pytest.approx(ours["average_visibility"], rel=VISIBILITY_REL)
    assert barn["characteristic_dimension"] == pytest.approx(ours["characteristic_dimension"], rel=CHARDIM_REL)
    lo, hi = DISPERSION_RATIO
    assert lo * ours["dispersion"] <= barn["dispersion"] <= hi * ours["dispersion"]


def test_the_map_shows_door_leaves_at_their_open_limit(tmp_path):
    """map.pgm is the planning scene: the closed doorway is free, the opened leaf's cells are occupied."""
    world = worldgen.generate("door", seed=0, state="closed", door_y=0.0, size=[8.0, 4.0])
    folder = world.write(tmp_path, preview=False)
    occupied, res, origin = read_map(folder)
    door = world.metadata["doors"][0]
    centre = np.array([door["passage"]["center"]])
    assert not occupied[cells_of(centre, occupied, res, origin)[0]]  # the doorway, where the closed leaf stands
    # The opened leaf: half a leaf from the hinge, along the open direction.
    hinge = np.array(door["hinge"][:2])
    normal = np.array(door["passage"]["normal"])
    assert occupied[cells_of((hinge + normal * (door["width"] / 2))[None], occupied, res, origin)[0]]
