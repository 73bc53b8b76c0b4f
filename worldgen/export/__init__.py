"""Writers: one module per file a world folder holds (world.sdf, world.mjcf.xml, world.urdf, meshes,
world.json, scenario.yaml, preview.png), plus the formats' names and the XML helpers they share."""

__all__: list[str] = []
