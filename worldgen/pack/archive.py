"""A pack as one file: ``PACK.tar.gz``, byte for byte the same for the same pack.

Members are sorted, owned by uid/gid 0 with empty owner names, mtime 0, mode
0644 (folders 0755), and the gzip header carries no name and mtime 0. The build
state (``.build/``) stays out. Reading never extracts blindly: only regular
files and folders under the one top-level folder are accepted, and a member
whose name is absolute, has ``..`` or leaves that folder is refused.
"""

from __future__ import annotations

import gzip
import io
import json
import tarfile
from pathlib import Path, PurePosixPath
from typing import Optional

from worldgen.errors import OutputError, ParameterError
from worldgen.files import MANIFEST_NAME, WORLDS_DIR, write_atomically
from worldgen.pack.manifest import world_folder

__all__ = ["write_archive", "ArchiveReader", "is_archive", "SUFFIX"]

SUFFIX = ".tar.gz"
MAX_MEMBERS = 10_000_000


def is_archive(path) -> bool:
    return Path(path).is_file() and str(path).endswith((SUFFIX, ".tgz"))


def write_archive(pack_dir, out: Optional[Path] = None) -> Path:
    """Write ``pack_dir`` (which must hold manifest.json) to ``out`` (default PACK.tar.gz)."""
    pack_dir = Path(pack_dir)
    if not (pack_dir / MANIFEST_NAME).is_file():
        raise ParameterError(f"'{pack_dir}' is not a finished pack (no {MANIFEST_NAME}); build it first")
    top = pack_dir.resolve().name
    out = Path(out) if out is not None else pack_dir.resolve().parent / f"{top}{SUFFIX}"
    listed = {world_folder(w).split("/", 1)[1] for w in json.loads((pack_dir / MANIFEST_NAME).read_bytes())["worlds"]}
    paths = []
    for p in pack_dir.rglob("*"):
        rel = p.relative_to(pack_dir)
        if any(part.startswith(".") for part in rel.parts):
            continue  # build state and temporary leftovers are not part of the pack
        if len(rel.parts) >= 2 and rel.parts[0] == WORLDS_DIR and rel.parts[1] not in listed:
            continue  # a world the manifest does not list is not part of the pack either
        if p.is_symlink():
            raise OutputError(f"refusing to archive symlink '{p}'")
        paths.append(rel)
    raw = io.BytesIO()
    with tarfile.open(fileobj=raw, mode="w", format=tarfile.PAX_FORMAT) as tar:
        tar.addfile(_info(top, None))
        for rel in sorted(paths, key=lambda r: r.as_posix()):
            name = f"{top}/{rel.as_posix()}"
            full = pack_dir / rel
            if full.is_dir():
                tar.addfile(_info(name, None))
            else:
                data = full.read_bytes()
                tar.addfile(_info(name, len(data)), io.BytesIO(data))
    packed = io.BytesIO()
    with gzip.GzipFile(filename="", mode="wb", fileobj=packed, mtime=0, compresslevel=6) as gz:
        gz.write(raw.getvalue())
    write_atomically(out, packed.getvalue())
    return out


def _info(name: str, size: Optional[int]) -> tarfile.TarInfo:
    info = tarfile.TarInfo(name)
    info.mtime = 0
    info.uid = info.gid = 0
    info.uname = info.gname = ""
    if size is None:
        info.type, info.mode = tarfile.DIRTYPE, 0o755
    else:
        info.size, info.mode = size, 0o644
    return info


class ArchiveReader:
    """Files of an archived pack, read in memory by their path relative to the pack."""

    def __init__(self, path):
        self.path = Path(path)
        try:
            tar = tarfile.open(self.path, mode="r:gz")
            members = tar.getmembers()
        except (OSError, tarfile.TarError, EOFError) as exc:
            raise ParameterError(f"'{self.path}' is not a readable pack archive: {exc}") from None
        self._tar = tar
        self._files: dict[str, tarfile.TarInfo] = {}
        top = None
        for m in members[:MAX_MEMBERS]:
            pure = PurePosixPath(m.name)
            if pure.is_absolute() or ".." in pure.parts or not pure.parts or "\\" in m.name:
                raise ParameterError(f"archive '{self.path}' has an unsafe member name {m.name!r}")
            if top is None:
                top = pure.parts[0]
            if pure.parts[0] != top:
                raise ParameterError(f"archive '{self.path}' has members outside its folder '{top}': {m.name!r}")
            if m.isdir():
                continue
            if not m.isfile():
                raise ParameterError(f"archive '{self.path}' member {m.name!r} is not a regular file")
            rel = "/".join(pure.parts[1:])
            if rel:
                self._files[rel] = m
        if MANIFEST_NAME not in self._files:
            raise ParameterError(f"archive '{self.path}' holds no {MANIFEST_NAME} at its top folder")
        self.top = top

    def names(self) -> list[str]:
        return sorted(self._files)

    def exists(self, rel: str) -> bool:
        return rel in self._files

    def read(self, rel: str) -> bytes:
        member = self._files.get(rel)
        if member is None:
            raise FileNotFoundError(rel)
        fh = self._tar.extractfile(member)
        return fh.read() if fh is not None else b""

    def extract_folder(self, prefix: str, dest: Path) -> Path:
        """Write the files under ``prefix/`` into ``dest`` (member names were checked above)."""
        dest = Path(dest)
        for rel in self.names():
            if rel.startswith(prefix.rstrip("/") + "/"):
                target = dest / rel
                target.parent.mkdir(parents=True, exist_ok=True)
                target.write_bytes(self.read(rel))
        return dest / prefix

    def close(self) -> None:
        self._tar.close()
