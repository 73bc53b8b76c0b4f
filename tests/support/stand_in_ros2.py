"""A stand-in for ``ros2 launch`` of a world's ROS 2 bundle (docs/ros2.md), for the campaign's documented
command template: it writes what one run of the bundle's launch file leaves in ``out:=``, without ROS.

    python tests/support/stand_in_ros2.py launch WORLD/ros2/launch/NAME.launch.py task:=T run:=K out:=DIR

The bag ``DIR/<world folder>__<task>__run<K>`` (the task's reference path, written with the project's bag
writer) and its result file ``<bag>.result.yaml`` with ``outcome: succeeded``; with the environment
variable ``STAND_IN_OUTCOME=crashed`` the bag is cut short and the result says ``crashed``, as the launch
file writes it when the goal sender dies. Exit status 0 either way, as ``ros2 launch`` exits.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

__all__ = ["main"]


def main(argv: list[str]) -> int:
    import yaml

    if len(argv) < 2 or argv[0] != "launch":
        print(f"stand-in ros2: only 'launch FILE ARG:=VALUE...' is known, got {argv}", file=sys.stderr)
        return 2
    launch = Path(argv[1])
    world = launch.parent.parent.parent
    args = dict(a.split(":=", 1) for a in argv[2:])
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from support.runs import along, write_bag

    task, run, out = args["task"], int(args["run"]), Path(args["out"])
    out.mkdir(parents=True, exist_ok=True)
    name = f"{world.name}__{task}__run{run}"
    outcome = os.environ.get("STAND_IN_OUTCOME", "succeeded")
    trajectory = along(world)
    if outcome == "crashed":
        trajectory = trajectory[: max(2, len(trajectory) // 5)]
    write_bag(out / name, world, trajectory, task=task, run=str(run))
    (out / f"{name}.result.yaml").write_text(yaml.safe_dump({"outcome": outcome, "task": task, "run": run}))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
