"""What a Gazebo server prints: the lines that say nothing about the world, and the problems among the rest.

:func:`problems_in` is what :meth:`worldgen.sim.gazebo.GazeboServer.problems` returns: the error and warning
lines of a log without :data:`HARMLESS` lines and without the lines every actor makes the server print
(:data:`ACTOR_NOTES`, each at most once per actor). Both releases print them alike (Fortress 6.18 and
Harmonic 8.14, measured here).
"""

from __future__ import annotations

import re

__all__ = ["HARMLESS", "ACTOR_NOTES", "SENSOR_FRAME_NOTE", "ANSI", "problems_in", "without_harmless"]

#: Lines Gazebo prints that say nothing about the world, each with why it is harmless.
HARMLESS: dict[str, str] = {
    "Library error: libignition-tools-backward.so not found":
        "ign-tools' optional backtrace helper, absent from Debian's ign-tools; printed by every ign call",
    "Error launching Remotery: Can't bind a socket for the server":
        "ign-common's profiler (Remotery, compiled into the 6.18 build) listens on TCP port 1500 (measured: "
        "whatever RMT_PORT says) and finds it taken when another Gazebo runs on the machine; profiling only",
}

ANSI = re.compile(r"\x1b\[[0-9;]*m")

#: The one element sdformat 14 (Harmonic) warns about in worldgen's robot, with why it is written all the same:
#: gz-sensors 8 takes a sensor's message frame from it and from nothing else (measured here: without it a scan's
#: frame is ``robot::base_scan::lidar``, with it ``base_scan``); SDFormat's spec has no sensor frame element, and
#: sdformat copies an element it does not know into the sensor, where gz-sensors reads it.
SENSOR_FRAME_NOTE = "XML Element[gz_frame_id], child of element[sensor], not defined in SDF"

#: Lines a skin-less actor (worldgen's movers and people) makes Gazebo 6.18 and 8.14 print, once per actor, with
#: why it says nothing wrong about the world; :func:`problems_in` drops each at most once per actor.
ACTOR_NOTES: dict[str, str] = {
    "Link's parent entity": "the Physics system visits an actor's link, finds no model for it and skips it: "
                            "actors have no physics in Gazebo Sim (the script moves them)",
    "Collision's parent entity": "the same for the actor link's collision element",
    "Invalid mesh filename extension": "the rendering scene tries the actor's skin, sdformat's placeholder name "
                                       "__default__ (worldgen writes no skin), then draws the actor's links along "
                                       "the script instead (gz-sim pull request 1947)",
    "Actor skin mesh": "the same skin lookup, reported a second time",
}


def problems_in(log: str, actors: int = 0) -> list[str]:
    """The error and warning lines of a Gazebo log (Gazebo's ``[Err]``/``[Wrn]``, sdformat's ``Error [``/``Warning
    [``), without colour codes, without :data:`HARMLESS` lines, without up to ``actors`` of each
    :data:`ACTOR_NOTES` line, and without :data:`SENSOR_FRAME_NOTE` lines (a spawned robot's sensors)."""
    out, left = [], {note: actors for note in ACTOR_NOTES}
    for line in ANSI.sub("", log).splitlines():
        if any(known in line for known in HARMLESS) or SENSOR_FRAME_NOTE in line:
            continue
        note = next((n for n in ACTOR_NOTES if n in line), None)
        if note is not None and left[note] > 0:
            left[note] -= 1
            continue
        if "[Err]" in line or "[Wrn]" in line or "Warning [" in line or "error" in line.lower():
            out.append(line.strip())
    return out


def without_harmless(text: str) -> str:
    """``text`` without its :data:`HARMLESS` lines."""
    return "\n".join(x for x in text.splitlines() if not any(k in x for k in HARMLESS))
