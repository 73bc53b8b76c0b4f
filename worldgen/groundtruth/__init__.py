"""Ground truth for test oracles: lidar ranges, the occupancy map, difficulty metrics.

Each module reads the Scene (and the World's tasks and feasibility paths) and
returns plain data; :mod:`worldgen.export.metadata` and :mod:`worldgen.world`
put it into world.json and beside it.
"""

__all__: list[str] = []
