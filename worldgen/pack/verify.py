"""``worldgen pack verify``: does a pack (folder or archive) hold exactly what its manifest says?

Per world, in order: world.json is listed and parses, every listed file exists
with its recorded sha256, world.json follows the shipped schema and names the
same world (id, generator, seed); then index.csv must be the one the manifest
gives. With ``regenerate``, each world is also rebuilt from its generator,
params and seed and compared byte for byte (``worldgen check`` on its folder;
from an archive, on a temporary copy of the folder).
"""

from __future__ import annotations

import hashlib
import tempfile
from pathlib import Path
from typing import Iterator

from worldgen.files import INDEX_NAME, METADATA_NAME, WORLDS_DIR
from worldgen.pack.manifest import index_bytes
from worldgen.pack.pack import Pack

__all__ = ["verify_pack"]


def verify_pack(path, regenerate: bool = False) -> Iterator[tuple[bool, str]]:
    """Yield ``(ok, line)`` per world, then one for index.csv."""
    from worldgen.export.metadata import validate

    pack = Pack.open(path)
    try:
        for world in pack:
            yield _world(pack, world, validate, regenerate)
        src = pack.source
        listed = {w.folder for w in pack}
        for folder in sorted({"/".join(n.split("/")[:2]) for n in src.names() if n.startswith(WORLDS_DIR + "/")}):
            if folder not in listed:
                yield False, f"FAIL {folder}: not in the manifest (left by another build?)"
        ok = src.exists(INDEX_NAME) and src.read(INDEX_NAME) == index_bytes(pack.manifest)
        yield ok, f"{'OK' if ok else 'FAIL'} {INDEX_NAME}" + ("" if ok else ": does not match the manifest")
    finally:
        pack.close()


def _world(pack: Pack, world, validate, regenerate: bool) -> tuple[bool, str]:
    src = pack.source
    meta_rel = f"{world.folder}/{METADATA_NAME}"
    if meta_rel not in world.files:
        return False, f"FAIL {world.world_id}: files: {METADATA_NAME} is not listed in the manifest"
    for rel, digest in sorted(world.files.items()):
        if not rel.startswith(world.folder + "/"):
            return False, f"FAIL {world.world_id}: paths: {rel} is outside the world's folder"
        if not src.exists(rel):
            return False, f"FAIL {world.world_id}: files: {rel} is missing"
        if hashlib.sha256(src.read(rel)).hexdigest() != digest:
            return False, f"FAIL {world.world_id}: files: {rel} does not match its sha256"
    try:
        meta = world.metadata  # its bytes were checked against the manifest's sha256 above
        validate(meta)
    except Exception as exc:  # a bad world.json is a verdict, not a crash
        return False, f"FAIL {world.world_id}: schema: {' '.join(str(exc).split())[:200]}"
    if (meta.get("world_id"), meta.get("generator"), meta.get("seed")) != (world.world_id, world.generator, world.seed):
        return False, f"FAIL {world.world_id}: metadata: {METADATA_NAME} names another world"
    if regenerate:
        from worldgen.verify import check_folder

        with tempfile.TemporaryDirectory(prefix="worldgen-verify-") as tmp:
            folder = src.extract_folder(world.folder, Path(tmp)) if pack.archive else world.path
            outcome = check_folder(folder)
        if not outcome.ok:
            return False, f"FAIL {world.world_id}: {outcome.check}: {outcome.detail}"
    return True, f"OK {world.world_id}"
