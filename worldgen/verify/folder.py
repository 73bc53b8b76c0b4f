"""``worldgen check``: re-verify a world folder that someone received.

The checks run in this order, and the first that fails is the answer (later
ones would only repeat it in other words):

``metadata``     world.json is there and is a JSON object;
``paths``        every path in ``files`` stays inside the folder (no ``..``, no
                 absolute path, no symlink out), before anything is opened;
``files``        every listed file exists and its SHA-256 is the recorded one;
``schema``       world.json follows the shipped JSON Schema (jsonschema, a core
                 dependency for this reason);
``regenerate``   generator + params + seed (then ``edits``, each re-proved, for
                 a curriculum's edited level) give the recorded ``content_hash``;
``feasibility``  the feasibility re-run agrees: the same verdict, the same
                 robot, spawns and goals, each path length within 1e-6 m, and
                 the recorded waypoints kept clear by FCL in the regenerated scene
                 (doors at their open limit, as the reference paths assume);
``timed``        with people, every ``tasks[].timed_path`` is re-proved from
                 world.json's own data (not by re-running the certificate's
                 search): rows from the spawn at t = 0 to the goal at
                 ``arrival_time``, times increasing, no faster than
                 ``robot.max_speed``, on the recorded path (consecutive rows on
                 one leg of it), kept clear by FCL in the regenerated scene, and,
                 sampled every 2 ms against every person's
                 ``trajectory`` (straight between rows, standing after the last),
                 never closer than ``robot.radius + robot.clearance + radius``
                 (+ ``robot.tracking_margin``) plus what the two could close
                 between samples; and, where world.json states them, within
                 ``robot.max_acceleration`` and ``robot.max_turn_rate`` (a stand
                 at every turn) (:mod:`worldgen.verify.timed`);
``reproduce``    when this worldgen version wrote the world: a fresh export gives
                 world.json and every listed file byte for byte (another version
                 may format files differently, so there this check is skipped and
                 the OK line says so).

preview.png is not checked: it is a picture, not listed in ``files`` (see
:mod:`worldgen.export.preview`).
"""

from __future__ import annotations

import copy
import hashlib
import json
import logging
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import Any, Optional

import numpy as np

from worldgen.errors import WorldgenError
from worldgen.files import METADATA_NAME

__all__ = ["CHECKS", "Outcome", "check_folder", "load_world", "LENGTH_TOLERANCE"]

CHECKS = ("metadata", "paths", "files", "schema", "regenerate", "feasibility", "timed", "reproduce")
#: Recorded and re-run path lengths may differ by this much (m): the 1e-6 of the
#: contract plus half a unit in the 6th decimal that world.json rounds to.
LENGTH_TOLERANCE = 1e-6 + 5e-7
#: Where a long check says which stage it is in (worldgen.cli.progress shows it on a terminal).
_progress = logging.getLogger("worldgen.progress")


@dataclass(frozen=True)
class Outcome:
    """The verdict on one folder: ``check`` and ``detail`` name the first failure."""

    folder: Path
    ok: bool
    check: Optional[str] = None
    detail: str = ""
    note: str = ""

    def line(self) -> str:
        if self.ok:
            return f"OK {self.folder}" + (f" ({self.note})" if self.note else "")
        return f"FAIL {self.folder}: {self.check}: {self.detail}"


class _Fail(WorldgenError):
    """The first check that fails; caught in check_folder, which turns it into the Outcome it returns."""

    def __init__(self, check: str, detail: str):
        super().__init__(detail)
        self.check, self.detail = check, " ".join(str(detail).split())


def check_folder(folder) -> Outcome:
    """Run every check on ``folder``; never raises for a bad world, only reports it."""
    folder = Path(folder)
    try:
        _progress.info("checking %s: hashes", folder)
        meta = _metadata(folder)
        entries = _paths(folder, meta)
        _files(folder, entries)
        _progress.info("checking %s: schema", folder)
        _schema(meta)
        _progress.info("checking %s: regenerating %s seed %s (its own seed, no level draws)", folder,
                       meta.get("generator"), meta.get("seed"))
        world = _regenerate(meta)
        _progress.info("checking %s: feasibility and timed paths", folder)
        _feasibility(meta, world)
        _timed(meta, world)
        _progress.info("checking %s: rendering every file again", folder)
        note = _reproduce(folder, meta, world, entries)
    except _Fail as f:
        return Outcome(folder, False, f.check, f.detail)
    return Outcome(folder, True, note=note)


def load_world(folder):
    """The World a world folder holds, rebuilt from its world.json (generator, seed, params, then its
    ``edits``) and proven the one recorded (the same ``content_hash``); the files themselves are not read.
    A folder that holds no such world is one :class:`~worldgen.errors.ParameterError` line."""
    from worldgen.errors import ParameterError

    folder = Path(folder)
    try:
        meta = _metadata(folder)
        _schema(meta)
        return _regenerate(meta)
    except _Fail as f:
        raise ParameterError(f"'{folder}' holds no world worldgen can rebuild: {f.check}: {f.detail}") from None


# -- the checks ----------------------------------------------------------------

def _metadata(folder: Path) -> dict:
    path = folder / METADATA_NAME
    if not path.is_file():
        raise _Fail("metadata", f"no {METADATA_NAME} in the folder")
    try:
        meta = json.loads(path.read_bytes())
    except (OSError, ValueError) as exc:
        raise _Fail("metadata", f"{METADATA_NAME} cannot be read as JSON: {exc}") from None
    if not isinstance(meta, dict):
        raise _Fail("metadata", f"{METADATA_NAME} is not a JSON object")
    return meta


def _paths(folder: Path, meta: dict) -> list[tuple[str, str, str]]:
    """``[(key, relative path, sha256)]``, each path proven to stay inside ``folder``."""
    files = meta.get("files")
    if not isinstance(files, dict):
        raise _Fail("paths", "world.json has no 'files' object")
    root = folder.resolve()
    out = []
    for key in sorted(files):
        entry = files[key]
        rel = entry.get("path") if isinstance(entry, dict) else None
        digest = entry.get("sha256") if isinstance(entry, dict) else None
        if not isinstance(rel, str) or not isinstance(digest, str):
            raise _Fail("paths", f"files.{key} needs a string 'path' and 'sha256'")
        pure = PurePosixPath(rel)
        if (not rel or pure.is_absolute() or ".." in pure.parts or "\\" in rel or "\0" in rel
                or (len(rel) > 1 and rel[1] == ":")):
            raise _Fail("paths", f"files.{key} path {rel!r} is not a plain path inside the world folder")
        if not (folder / rel).resolve().is_relative_to(root):  # a symlink pointing out
            raise _Fail("paths", f"files.{key} path {rel!r} leads outside the world folder")
        out.append((key, rel, digest))
    return out


def _files(folder: Path, entries) -> None:
    for key, rel, digest in entries:
        path = folder / rel
        if not path.is_file():
            raise _Fail("files", f"{rel} is missing")
        found = hashlib.sha256(path.read_bytes()).hexdigest()
        if found != digest:
            raise _Fail("files", f"{rel} has sha256 {found[:12]}..., world.json records {digest[:12]}...")


def _schema(meta: dict) -> None:
    import jsonschema

    from worldgen.export.metadata import schema

    validator = jsonschema.Draft202012Validator(schema())
    error = jsonschema.exceptions.best_match(validator.iter_errors(meta))
    if error is not None:
        where = "/".join(str(p) for p in error.absolute_path) or "(top level)"
        raise _Fail("schema", f"{where}: {_short(error.message)}")


def _regenerate(meta: dict):
    import worldgen

    try:
        world = worldgen.generate(meta["generator"], seed=meta["seed"],
                                  allow_infeasible=meta["feasibility"]["allow_infeasible"], **meta["params"])
    except WorldgenError as exc:
        raise _Fail("regenerate", f"{meta['generator']} seed {meta['seed']} with the recorded params: {exc}") from None
    if meta.get("edits"):  # a curriculum's edited level: the generated world, then its edits, each re-proved
        from worldgen.verify.edits import replay_edits

        try:
            world = replay_edits(world, meta["edits"])
        except WorldgenError as exc:
            raise _Fail("regenerate", f"edits: {exc}") from None
    world.set_provenance(preset=meta.get("preset"))  # not a parameter: where the world came from (world.json and folder name)
    request = meta.get("difficulty_request")  # not a parameter either: how a world at a level was drawn
    if request:
        last = request["draws"][-1] if request.get("draws") else {}
        if (last.get("seed"), last.get(request.get("knob"))) != (meta["seed"], meta["params"].get(request.get("knob"))):
            raise _Fail("regenerate", "difficulty_request's last draw is not this world's seed and "
                                      f"{request.get('knob')}")
        world.set_provenance(difficulty_request=request)
    if world.content_hash != meta["content_hash"]:
        raise _Fail("regenerate", f"content_hash {_h(world.content_hash)} regenerated, "
                                  f"{_h(meta['content_hash'])} recorded{_versions(meta)}")
    return world


def _feasibility(meta: dict, world) -> None:
    from worldgen.feasibility.collision import Colliders
    from worldgen.feasibility.verify import verify_path
    from worldgen.floats import round_float
    from worldgen.scene.doors import open_scene

    report, robot = world.feasibility, world.robot
    if bool(meta["feasibility"]["feasible"]) != report.feasible:
        failed = ", ".join(c.name for c in report.failed()) or "none"
        raise _Fail("feasibility", f"recorded feasible={meta['feasibility']['feasible']}, "
                                   f"re-run feasible={report.feasible} (failed: {failed})")
    recorded_robot = meta["robot"]
    for name in ("radius", "height", "clearance"):
        if round_float(getattr(robot, name)) != recorded_robot[name]:
            raise _Fail("feasibility", f"robot.{name} {recorded_robot[name]} recorded, "
                                       f"{round_float(getattr(robot, name))} from the params")
    if len(meta["tasks"]) != len(world.tasks):
        raise _Fail("feasibility", f"{len(meta['tasks'])} tasks recorded, {len(world.tasks)} regenerated")
    colliders = None
    for task, rerun, path in zip(meta["tasks"], world.tasks, report.paths):
        for end in ("spawn", "goal"):
            fresh = [round_float(v) for v in getattr(rerun, end).as_list()]
            if fresh != task[end]:
                raise _Fail("feasibility", f"{task['id']} {end} {task[end]} recorded, {fresh} regenerated")
        if (task["path"] is None) != (path is None):
            raise _Fail("feasibility", f"{task['id']}: a path is {'missing' if path is not None else 'recorded'}"
                                       f" where the re-run found {'one' if path is not None else 'none'}")
        if path is None:
            continue
        recorded = task["path"]["length"]
        if not abs(recorded - path.length) <= LENGTH_TOLERANCE:
            raise _Fail("feasibility", f"{task['id']} path length {recorded} m recorded, {path.length:.6f} m re-run")
        if colliders is None:  # reference paths go through doors at their open limit, as the checker plans
            colliders = Colliders(open_scene(world.scene))
        # The path a test will use is the recorded one: prove it, not only the re-run's.
        nearest = verify_path(colliders, robot, np.asarray(task["path"]["waypoints"], dtype=float))
        if report.feasible and nearest.distance < robot.clearance - 1e-6:
            raise _Fail("feasibility", f"{task['id']} recorded path comes {nearest.distance:.6f} m from "
                                       f"{nearest.name}, under the clearance {robot.clearance} m")


def _timed(meta: dict, world) -> None:
    from worldgen.verify.timed import TimedPathError, check_timed

    try:
        check_timed(meta, world)
    except TimedPathError as exc:
        raise _Fail("timed", str(exc)) from None


def _reproduce(folder: Path, meta: dict, world, entries) -> str:
    import worldgen
    from worldgen.export.formats import ALL_FORMATS, FILE_NAMES, unavailable_formats

    if meta.get("worldgen_version") != worldgen.__version__:
        return f"written by worldgen {meta.get('worldgen_version')}, not compared byte for byte"
    listed = {key for key, _, _ in entries}
    formats = [f for f in ALL_FORMATS if f in listed]
    if not formats:
        raise _Fail("reproduce", "world.json lists none of the formats " + ", ".join(ALL_FORMATS))
    # A format whose extra is not installed here (usd without usd-core) is not rendered again: its file's
    # hash was checked against world.json above, the world it describes was regenerated and re-proved, and
    # every other file is still compared byte for byte. Said in the verdict, never a failure.
    missing = unavailable_formats(formats)
    note = (f"{', '.join(FILE_NAMES[f] for f in missing)} not rendered again: the optional dependency is not "
            "installed here (sha256 checked against world.json)") if missing else ""
    formats = [f for f in formats if f not in missing]
    if not formats:
        return note
    sdf_version = _sdf_version(folder / FILE_NAMES["sdf"]) if "sdf" in listed else "1.9"
    blobs = world.folder_blobs(formats, sdf_version, preview=False)
    fresh = json.loads(blobs.pop(METADATA_NAME))
    where = _first_difference(_without_formats(meta, missing), fresh)
    if where is not None:
        raise _Fail("reproduce", f"world.json differs from a fresh export at {where}")
    # world.json equal means every listed hash equal; still, say which file if one is not.
    for key, rel, digest in entries:
        if key in missing:
            continue
        data = blobs.get(rel)
        if data is None or hashlib.sha256(data).hexdigest() != digest:
            raise _Fail("reproduce", f"{rel} differs from a fresh export")
    return note


def _without_formats(meta: dict, formats) -> dict:
    """world.json as it would read had ``formats`` not been written: an optional format is named only in
    ``files`` and in the movers' and people's ``formats`` notes (docs/world-json.md)."""
    if not formats:
        return meta
    meta = copy.deepcopy(meta)
    for f in formats:
        meta["files"].pop(f, None)
        for entry in meta.get("dynamic_obstacles", []) + meta.get("people", []):
            if isinstance(entry, dict) and isinstance(entry.get("formats"), dict):
                entry["formats"].pop(f, None)
    return meta


# -- helpers -------------------------------------------------------------------

def _sdf_version(path: Path) -> str:
    from lxml import etree

    from worldgen.export.xml import safe_parser

    try:
        root = etree.parse(str(path), safe_parser()).getroot()
    except (OSError, etree.XMLSyntaxError) as exc:
        raise _Fail("reproduce", f"{path.name} cannot be parsed: {exc}") from None
    return root.get("version", "1.9")


def _first_difference(a: Any, b: Any, where: str = "") -> Optional[str]:
    """The JSON path of the first place ``a`` and ``b`` differ, or None; keys in sorted order."""
    if type(a) is not type(b) and not (isinstance(a, (int, float)) and isinstance(b, (int, float))
                                       and not isinstance(a, bool) and not isinstance(b, bool)):
        return f"{where or '(top level)'} ({_short(json.dumps(a))} recorded, {_short(json.dumps(b))} fresh)"
    if isinstance(a, dict):
        for key in sorted(set(a) | set(b)):
            if key not in a or key not in b:
                return f"{where}.{key} ({'only fresh' if key not in a else 'only recorded'})".lstrip(".")
            found = _first_difference(a[key], b[key], f"{where}.{key}" if where else key)
            if found:
                return found
        return None
    if isinstance(a, list):
        if len(a) != len(b):
            return f"{where} ({len(a)} items recorded, {len(b)} fresh)"
        for i, (x, y) in enumerate(zip(a, b)):
            found = _first_difference(x, y, f"{where}[{i}]")
            if found:
                return found
        return None
    if a != b:
        return f"{where} ({_short(json.dumps(a))} recorded, {_short(json.dumps(b))} fresh)"
    return None


def _short(text: str, limit: int = 120) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _h(content_hash: str) -> str:
    return content_hash[:19] + "..." if len(content_hash) > 22 else content_hash


def _versions(meta: dict) -> str:
    import worldgen

    written = meta.get("worldgen_version")
    return "" if written == worldgen.__version__ else f" (written by worldgen {written}, checked by {worldgen.__version__})"
