"""World packs: many worlds from a recipe, built in parallel, listed with every file's hash.

One module per concern: :mod:`.recipe` (the YAML), :mod:`.build` (parallel,
resumable build), :mod:`.manifest` (manifest.json, index.csv), :mod:`.pack`
(``Pack.open``), :mod:`.where` (metric filters), :mod:`.archive` (one .tar.gz),
:mod:`.verify` (hash, schema and regeneration checks).
"""

from worldgen.pack.archive import write_archive
from worldgen.pack.build import BuildSummary, build_pack
from worldgen.pack.pack import Pack, PackWorld
from worldgen.pack.recipe import Recipe, load_recipe, parse_recipe
from worldgen.pack.verify import verify_pack

__all__ = ["Pack", "PackWorld", "Recipe", "BuildSummary", "load_recipe", "parse_recipe", "build_pack",
           "verify_pack", "write_archive"]
