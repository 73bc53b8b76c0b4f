"""The JSON Schema of world.json (``world.schema.json``), shipped as package data."""

__all__: list[str] = []
