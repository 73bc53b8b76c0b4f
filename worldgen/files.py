"""The files worldgen writes: their names, and writing them so that no reader ever sees half of one.

Every stage names a file through the constants here (``"world.json"`` is written once, in this
module), and every file or folder a command leaves behind goes through :func:`write_atomically`,
:func:`write_folder_atomically` or :func:`atomic_folder` (a file another program made, through
:func:`move_into_place`): written beside its target, flushed, then renamed into place.
"""

from __future__ import annotations

import errno
import json
import os
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator, Mapping

from worldgen.errors import OutputError

__all__ = ["METADATA_NAME", "SCENARIO_NAME", "PREVIEW_NAME", "MAP_IMAGE_NAME", "MAP_YAML_NAME", "SDF_NAME", "MJCF_NAME",
           "URDF_NAME", "USDA_NAME", "USDC_NAME", "MANIFEST_NAME", "INDEX_NAME", "WORLDS_DIR", "BUILD_STATE_DIR",
           "REPORT_JSON_NAME", "REPORT_CSV_NAME", "REPORT_MD_NAME", "REPORT_RUNS_DIR", "CAMPAIGN_RECIPE_NAME",
           "VERDICTS_NAME", "FAILURES_NAME", "STRATEGY_NAME", "FAILURE_MAP_NAME", "CAMPAIGN_STATE_DIR", "RUNS_DIR",
           "SHRUNK_DIR", "PLOTS_DIR", "creation_mode", "safe_relative", "write_atomically", "atomic_folder",
           "write_folder_atomically", "move_into_place", "refuse_other_world", "recorded_content_hash",
           "TERRAIN_MESH_NAME"]

#: A world folder: its ground truth, scenario, picture and nav2 map.
METADATA_NAME = "world.json"
SCENARIO_NAME = "scenario.yaml"
PREVIEW_NAME = "preview.png"
MAP_IMAGE_NAME = "map.pgm"
MAP_YAML_NAME = "map.yaml"
#: A world folder's file of each format (worldgen.export.formats tables them with their writers); a template of
#: worldgen/templates and the file a simulator is handed carry the same names.
SDF_NAME = "world.sdf"
MJCF_NAME = "world.mjcf.xml"
URDF_NAME = "world.urdf"
USDA_NAME = "world.usda"
USDC_NAME = "world.usdc"
#: The terrain's ground as one triangle mesh, for the formats that refer to mesh files (docs/terrain.md).
TERRAIN_MESH_NAME = "meshes/terrain.stl"
#: A pack folder: the manifest (written last: its presence means the build finished), the index, the worlds.
MANIFEST_NAME = "manifest.json"
INDEX_NAME = "index.csv"
WORLDS_DIR = "worlds"
#: A pack build's records of finished jobs, kept until the manifest is written (a resume reads them).
BUILD_STATE_DIR = ".build"
#: A report folder of ``worldgen judge`` (worldgen.judge.report): the report three ways, a picture per run.
REPORT_JSON_NAME = "report.json"
REPORT_CSV_NAME = "report.csv"
REPORT_MD_NAME = "report.md"
REPORT_RUNS_DIR = "runs"
#: A campaign folder (worldgen.campaign): the recipe as given, every run's verdict, the failed ones, the
#: search's state, the failure map (a table and plots), the report a reviewer reads first (REPORT_MD_NAME, as
#: a judge's report names it); the worlds are in WORLDS_DIR, what each run's system wrote in RUNS_DIR, each
#: distinct failure shrunk in SHRUNK_DIR, and the records of finished points (what a resume reads) in
#: CAMPAIGN_STATE_DIR.
CAMPAIGN_RECIPE_NAME = "campaign.yaml"
VERDICTS_NAME = "verdicts.csv"
FAILURES_NAME = "failures.csv"
STRATEGY_NAME = "strategy.json"
FAILURE_MAP_NAME = "failure_map.csv"
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


@contextmanager
def atomic_folder(out_dir: Path, name: str, what: str = "world folder") -> Iterator[Path]:
    """A temporary folder beside ``out_dir/name`` for the block to fill, which becomes ``out_dir/name`` whole
    when the block ends (replacing a folder there) or is removed when it raises.

    Every file in it is flushed to disk before the rename, so a crash leaves the old folder or the new one.
    An OSError in the block or in the rename is an OutputError naming ``what`` (``"report folder"``).
    """
    out_dir = Path(out_dir)
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
        yield tmp
        _sync_tree(tmp)
        os.chmod(tmp, creation_mode(0o777))
        _rename_folder(tmp, target)
    except OSError as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        raise OutputError(f"cannot write {what} '{target}': {exc.strerror or exc}") from None
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def write_folder_atomically(out_dir: Path, name: str, blobs: Mapping[str, bytes]) -> Path:
    """Write ``blobs`` (relative path -> bytes) as ``out_dir/name``; complete or absent."""
    with atomic_folder(out_dir, name) as tmp:
        for rel, data in sorted(blobs.items()):
            path = tmp / safe_relative(rel)
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data)
    return Path(out_dir) / name


def move_into_place(made: Path, target: Path) -> None:
    """Move the file or folder ``made`` (another program's output, e.g. a compiler's or a finished bag folder, on
    the same file system) to ``target`` whole: flushed, then renamed, so no reader ever runs or opens half of it."""
    _sync_file(Path(made))
    os.replace(made, target)


def _sync_file(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)  # fsync acts on the file, whatever the descriptor was opened for (POSIX)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _sync_tree(folder: Path) -> None:
    for path in sorted(folder.rglob("*")):
        if path.is_file() and not path.is_symlink():
            _sync_file(path)


def _rename_folder(tmp: Path, target: Path) -> None:
    try:
        os.rename(tmp, target)
        return
    except OSError as exc:
        if exc.errno not in (errno.EEXIST, errno.ENOTEMPTY):
            raise
    # The folder is there (a rebuild, or another worker of a pack writing the same world this very
    # moment): swap it out, then in; a folder another worker renames in between is swapped out too.
    old = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".old", dir=target.parent))
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
