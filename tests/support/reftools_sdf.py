"""The strict libsdformat checker (tests/tools/sdf_check.cc), built once per test session.

The program is compiled against sdformat12 into ``tests/.cache/`` under a name
that carries a digest of its source and of the compiler flags, so an edited
source or a changed libsdformat gives a fresh build and a stale binary is never
used. Where g++, pkg-config or the sdformat12 development files are missing,
tests that need the checker skip on a laptop and fail on CI
(``conftest.missing_tool``).
"""

from __future__ import annotations

import functools
import hashlib
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

from support import missing_tool

__all__ = ["SOURCE", "checker", "check_sdf", "check_robot_sdf", "dump_sdf"]

HERE = Path(__file__).resolve().parents[1]
SOURCE = HERE / "tools" / "sdf_check.cc"
CACHE = HERE / ".cache"
#: Generous: a cold build of the checker takes a few seconds here.
BUILD_TIMEOUT_S = 300
RUN_TIMEOUT_S = 60


@functools.lru_cache(maxsize=None)
def _build() -> str:
    """Path of the compiled checker, or the reason it cannot be built (prefixed 'missing:')."""
    compiler = shutil.which("g++")
    if compiler is None:
        return "missing:g++ (to build tests/tools/sdf_check.cc)"
    if shutil.which("pkg-config") is None:
        return "missing:pkg-config (to find libsdformat)"
    flags = subprocess.run(["pkg-config", "--cflags", "--libs", "sdformat12"], capture_output=True, text=True)
    if flags.returncode != 0:
        return "missing:libsdformat 12 development files (pkg-config sdformat12; apt-get install libsdformat-dev)"
    digest = hashlib.sha256(SOURCE.read_bytes() + flags.stdout.encode()).hexdigest()[:16]
    exe = CACHE / f"sdf_check-{digest}"
    if exe.exists():
        return str(exe)
    CACHE.mkdir(parents=True, exist_ok=True)
    # Build beside the target and rename, so a parallel session never runs half a binary.
    fd, tmp = tempfile.mkstemp(prefix=".sdf_check-", dir=CACHE)
    os.close(fd)
    cmd = [compiler, "-O1", "-std=c++17", str(SOURCE), "-o", tmp, *flags.stdout.split()]
    built = subprocess.run(cmd, capture_output=True, text=True, timeout=BUILD_TIMEOUT_S)
    if built.returncode != 0:
        os.unlink(tmp)
        raise RuntimeError(f"building the SDF checker failed:\n{' '.join(cmd)}\n{built.stderr}")
    os.chmod(tmp, 0o755)
    os.replace(tmp, exe)
    return str(exe)


def checker() -> str:
    """Path of the checker executable (skips or fails the test when it cannot be built)."""
    result = _build()
    if result.startswith("missing:"):
        missing_tool(result.split(":", 1)[1])
    return result


def _run(path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([checker(), *args, str(path)], capture_output=True, text=True, timeout=RUN_TIMEOUT_S)


def check_sdf(path) -> tuple[bool, list[str]]:
    """Strictly check the SDF file at ``path``: (ok, every message the checker printed)."""
    done = _run(path)
    messages = [line for line in (done.stderr + done.stdout).splitlines() if line.strip()]
    return done.returncode == 0 and not any(m.startswith("error:") for m in messages), messages


def check_robot_sdf(path) -> tuple[bool, list[str]]:
    """:func:`check_sdf` of a robot whose sensors name their frame with Gazebo's ``gz_frame_id``: a Gazebo
    extension that libsdformat's strict check calls undefined, so it is taken out (and must be there, once
    per sensor) and the rest is checked strictly."""
    import re
    from pathlib import Path

    from worldgen.export.robot import SENSOR_FRAME_ELEMENT

    text = Path(path).read_text()
    pattern = rf"\s*<{SENSOR_FRAME_ELEMENT}>[^<]*</{SENSOR_FRAME_ELEMENT}>"
    found, sensors = len(re.findall(pattern, text)), text.count("<sensor ")
    if found != sensors:
        return False, [f"error: {found} <{SENSOR_FRAME_ELEMENT}> for {sensors} sensors"]
    stripped = Path(path).with_name(Path(path).stem + ".strict.sdf")
    stripped.write_text(re.sub(pattern, "", text))
    return check_sdf(stripped)


def dump_sdf(path) -> dict:
    """What libsdformat understood of a valid file, as plain data.

    ``{"world", "gravity", "physics": (step, rtf), "update_rate", "lights",
    "models": {name: {"static", "pose"}}, "links": {"m::l": {"pose", "mass", "inertia"}},
    "collisions"/"visuals": {"m::l::c": (kind, [numbers or uri...])},
    "friction": {"m::l::c": (mu, mu2)}, "materials": {"m::l::v": (ambient, diffuse)},
    "joints": {"m::j": {"type", "parent", "child", "axis", "limits", "damping"}},
    "actors": {name: {"loop", "trajectories": {id: {"tension", "waypoints": [[t, x, y, z, roll, pitch, yaw]]}}}}}``.
    Link poses are in their model's frame, as libsdformat resolved them.
    """
    done = _run(path, "--dump")
    if done.returncode != 0:
        raise AssertionError(f"{path} fails the strict SDF check:\n{done.stderr}")
    out: dict = {"lights": [], "models": {}, "links": {}, "collisions": {}, "visuals": {},
                 "friction": {}, "materials": {}, "joints": {}, "actors": {}}
    for line in done.stdout.splitlines():
        kind, *rest = line.split()
        if kind == "world":
            out["world"] = rest[0]
        elif kind == "gravity":
            out["gravity"] = [float(v) for v in rest]
        elif kind == "physics":
            out["physics"] = (float(rest[0]), float(rest[1]))
        elif kind == "update_rate":
            out["update_rate"] = float(rest[0])
        elif kind == "light":
            out["lights"].append(rest[0])
        elif kind == "model":
            out["models"][rest[0]] = {"static": rest[2] == "1", "pose": [float(v) for v in rest[4:10]]}
        elif kind == "link":
            out["links"][rest[0]] = {"pose": [float(v) for v in rest[2:8]], "mass": float(rest[9]),
                                     "inertia": [float(v) for v in rest[11:14]]}
        elif kind in ("collision", "visual"):
            values = [rest[2]] + [float(v) for v in rest[3:]] if rest[1] == "mesh" else [float(v) for v in rest[2:]]
            out[kind + "s"][rest[0]] = (rest[1], values)
        elif kind == "friction":
            out["friction"][rest[0]] = (float(rest[1]), float(rest[2]))
        elif kind == "material":
            values = [float(v) for v in rest[1:]]
            out["materials"][rest[0]] = (values[:4], values[4:8])
        elif kind == "joint":
            fields = dict(zip(rest[1::2], rest[2::2]))
            joint = {"type": fields["type"], "parent": fields["parent"], "child": fields["child"]}
            if "axis" in fields:
                i = rest.index("axis")
                joint["axis"] = [float(v) for v in rest[i + 1:i + 4]]
                j = rest.index("limits")
                joint["limits"] = [float(v) for v in rest[j + 1:j + 3]]
                joint["damping"] = float(rest[rest.index("damping") + 1])
            out["joints"][rest[0]] = joint
        elif kind == "actor":
            out["actors"][rest[0]] = {"loop": rest[2] == "1", "trajectories": {}}
        elif kind == "trajectory":
            out["actors"][rest[0]]["trajectories"][int(rest[1])] = {"tension": float(rest[3]), "waypoints": []}
        elif kind == "waypoint":
            out["actors"][rest[0]]["trajectories"][int(rest[1])]["waypoints"].append([float(v) for v in rest[2:9]])
    return out
