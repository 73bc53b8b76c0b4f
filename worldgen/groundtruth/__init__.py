"""Ground truth for test oracles: lidar ranges, the occupancy map, difficulty metrics.

Each module reads the Scene (and the World's tasks and feasibility paths) and
returns plain data; :mod:`worldgen.export.metadata` and :mod:`worldgen.world`
put it into world.json and beside it. :func:`barn_metrics` is BARN's own five
metrics on a grid and a path of cells (:mod:`worldgen.groundtruth.barn`).
"""

from worldgen.groundtruth.barn import barn_metrics

__all__: list[str] = ["barn_metrics"]
