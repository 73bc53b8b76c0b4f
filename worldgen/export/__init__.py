"""Exporters: one module per format, each a function Scene -> lxml tree (or dict for metadata)."""
