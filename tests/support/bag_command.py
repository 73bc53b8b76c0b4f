"""A stand-in robot stack for the campaign's command system under test: run per world and task, it leaves (or
fails to leave) a rosbag2 bag written with the project's own writer (:func:`worldgen.ros.write_run`).

    python tests/support/bag_command.py MODE WORLD TASK RUN BAG

MODE says how the run goes:

- ``success``: the task's reference path at 0.5 m/s, a bag at BAG (reaches the goal, no contact);
- ``collision``: from the spawn straight into the world's first obstacle, a bag at BAG;
- ``crash``: prints a message and exits with status 1, no bag;
- ``nobag``: exits 0 and writes nothing;
- ``garbage``: exits 0 leaving a file at BAG that is no bag;
- ``hang``: starts a child in its process group that sleeps, then sleeps itself (for the timeout; the
  child's pid goes to BAG.child so a test can see the whole group was killed).
"""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

__all__ = ["main", "MODES"]

MODES = ("success", "collision", "crash", "nobag", "garbage", "hang")


def main(argv: list[str]) -> int:
    mode, world, task, run, bag = argv
    if mode not in MODES:
        print(f"unknown mode {mode!r}", file=sys.stderr)
        return 2
    if mode == "crash":
        print("stack crashed: lost the transform", file=sys.stderr)
        return 1
    if mode == "nobag":
        return 0
    if mode == "garbage":
        Path(bag).write_bytes(b"not a bag\n")
        return 0
    if mode == "hang":
        child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(300)"])
        Path(bag + ".child").write_text(str(child.pid))
        time.sleep(300)
        return 0
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    import worldgen.testing.oracles as oracles
    from support.runs import along, toward, write_bag

    folder = Path(world)
    if mode == "success":
        trajectory = along(folder)
    else:
        obstacle = next(e for e in oracles.load(folder).meta["entities"] if e["role"] == "obstacle")
        trajectory = toward(folder, obstacle["pose"][:2])
    write_bag(Path(bag), folder, trajectory, task=task, run=run)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
