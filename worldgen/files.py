"""The files worldgen writes: their names, and writing them so that no reader ever sees half of one.

Every stage names a file through the constants here (``"world.json"`` is written once, in this
module), and every file or folder a command leaves behind goes through :func:`write_atomically` or
:func:`write_folder_atomically`: written beside its target, flushed, then renamed into place.
"""

from __future__ import annotations

import errno
import json
import os
import shutil
import tempfile
from pathlib import Path
from typing import Mapping

from worldgen.errors import OutputError

__all__ = ["METADATA_NAME", "SCENARIO_NAME", "PREVIEW_NAME", "MAP_IMAGE_NAME", "MAP_YAML_NAME", "MANIFEST_NAME",
           "INDEX_NAME", "WORLDS_DIR", "BUILD_STATE_DIR", "creation_mode", "safe_relative", "write_atomically",
           "write_folder_atomically", "refuse_other_world", "recorded_content_hash", "CAMPAIGN_RECIPE_NAME", "VERDICTS_NAME",
           "FAILURES_NAME", "STRATEGY_NAME", "FAILURE_MAP_NAME", "REPORT_NAME", "CAMPAIGN_STATE_DIR", "RUNS_DIR",
           "SHRUNK_DIR", "PLOTS_DIR"]

#: A world folder: its ground truth, scenario, picture and nav2 map (the formats' files are named in
#: worldgen.export.formats).
METADATA_NAME = "world.json"
SCENARIO_NAME = "scenario.yaml"
PREVIEW_NAME = "preview.png"
MAP_IMAGE_NAME = "map.pgm"
MAP_YAML_NAME = "map.yaml"
#: A pack folder: the manifest (written last: its presence means the build finished), the index, the worlds.
MANIFEST_NAME = "manifest.json"
INDEX_NAME = "index.csv"
WORLDS_DIR = "worlds"
#: A pack build's records of finished jobs, kept until the manifest is written (a resume reads them).
BUILD_STATE_DIR = ".build"
#: A campaign folder (worldgen.campaign): the recipe as given, every run's verdict, the failed ones, the search's
#: state, the failure map (a table and plots), the report a reviewer reads first; the worlds are in WORLDS_DIR,
#: what each run's system wrote in RUNS_DIR, each distinct failure shrunk in SHRUNK_DIR, and the records of
#: finished points (what a resume reads) in CAMPAIGN_STATE_DIR.
CAMPAIGN_RECIPE_NAME = "campaign.yaml"
VERDICTS_NAME = "verdicts.csv"
FAILURES_NAME = "failures.csv"
STRATEGY_NAME = "strategy.json"
FAILURE_MAP_NAME = "failure_map.csv"
REPORT_NAME = "report.md"
CAMPAIGN_STATE_DIR = ".campaign"
RUNS_DIR = "runs"
SHRUNK_DIR = "shrunk"
PLOTS_DIR = "plots"


def creation_mode(full: int) -> int:
    """``full`` (0o666 for files, 0o777 for folders) less the process umask, as open() and mkdir() would give.

    tempfile makes 0600 files and 0700 folders whatever the umask; what is renamed
    into place must look as if it had been created there.
    """
    umask = os.umask(0)
    os.umask(umask)
    return full & ~umask


def safe_relative(rel: str) -> str:
    """``rel`` if it names a place inside a folder, else OutputError (a name never becomes a path outside)."""
    parts = Path(rel).parts
    if Path(rel).is_absolute() or ".." in parts or not parts:
        raise OutputError(f"refusing to write {rel!r} outside the world folder")
    return rel


def write_atomically(path: Path, data: bytes) -> None:
    """Write ``path`` whole or not at all: a temporary file beside it, fsync, rename."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, creation_mode(0o666))
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def recorded_content_hash(folder: Path):
    """The ``content_hash`` a world folder's world.json records, or None where there is none to read."""
    try:
        return json.loads((Path(folder) / METADATA_NAME).read_text(encoding="utf-8")).get("content_hash")
    except (OSError, ValueError, AttributeError):
        return None


def refuse_other_world(target: Path, content_hash: str) -> None:
    """Raise OutputError if ``target`` exists and is not a folder of the world ``content_hash``."""
    if not os.path.lexists(target):
        return
    recorded = recorded_content_hash(target)
    if recorded != content_hash:
        what = "another world" if recorded else "something that is not a world folder"
        raise OutputError(f"'{target}' already holds {what}; remove it, or pass overwrite=True to World.write "
                          f"(--overwrite on the command line) to replace it")


def write_folder_atomically(out_dir: Path, name: str, blobs: Mapping[str, bytes]) -> Path:
    """Write ``blobs`` (relative path -> bytes) as ``out_dir/name``; complete or absent."""
    if "/" in name or name in ("", ".", ".."):
        raise OutputError(f"refusing folder name {name!r}")
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        if not out_dir.is_dir():
            raise OutputError(f"output folder '{out_dir}' is not a folder")
        tmp = Path(tempfile.mkdtemp(prefix=f".{name}.", suffix=".tmp", dir=out_dir))
    except OutputError:
        raise
    except OSError as exc:
        raise OutputError(f"cannot write to output folder '{out_dir}': {exc.strerror or exc}") from None
    target = out_dir / name
    try:
        for rel, data in sorted(blobs.items()):
            path = tmp / safe_relative(rel)
            path.parent.mkdir(parents=True, exist_ok=True)
            with open(path, "wb") as fh:
                fh.write(data)
                fh.flush()
                os.fsync(fh.fileno())
        os.chmod(tmp, creation_mode(0o777))
        try:
            os.rename(tmp, target)
        except OSError as exc:
            if exc.errno not in (errno.EEXIST, errno.ENOTEMPTY):
                raise
            # The folder is there (a rebuild, or another worker of a pack writing the same world this very
            # moment): swap it out, then in; a folder another worker renames in between is swapped out too.
            old = Path(tempfile.mkdtemp(prefix=f".{name}.", suffix=".old", dir=out_dir))
            for k in range(8):
                try:
                    os.rename(target, old / f"w{k}")
                except FileNotFoundError:
                    pass
                try:
                    os.rename(tmp, target)
                    break
                except OSError as again:
                    if again.errno not in (errno.EEXIST, errno.ENOTEMPTY) or k == 7:
                        raise
            shutil.rmtree(old, ignore_errors=True)
    except OSError as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        raise OutputError(f"cannot write world folder '{target}': {exc.strerror or exc}") from None
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return target
