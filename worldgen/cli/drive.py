"""``worldgen drive``: a thin click layer over :func:`worldgen.sim.drive.drive`.

Exit status (docs/cli.md): 0 when the run is judged a success, 1 when it is not (a collision, the
goal missed), 2 on a usage mistake or a missing simulator or extra (one line on stderr).
"""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import click

from worldgen.cli.context import CONTEXT as _CONTEXT
from worldgen.export.contract import SIM_GZ_RELEASE, SIM_GZ_RELEASES

__all__ = ["drive_command"]

#: How the verdict line names what the robot followed (worldgen.sim.schedule.Plan's kinds, docs/drive.md).
_FOLLOWED = {"timed_path": "timed path", "static": "static path", "straight": "straight line"}


@click.command("drive", context_settings=_CONTEXT, epilog="""\b
Examples:
  worldgen drive worlds/cluttered-s0-55fec0f6 --sim gazebo --out runs
  worldgen drive worlds/cluttered-s0-55fec0f6 --sim gazebo --gz-release harmonic --out runs
  worldgen drive worlds/cluttered-s0-55fec0f6 --sim mujoco --out runs --straight   (into what stands between)
""")
@click.argument("world", type=click.Path(path_type=Path), metavar="WORLD")
@click.option("--sim", type=click.Choice(["gazebo", "mujoco"]), default="mujoco", show_default=True,
              help="The simulator: Gazebo headless (--gz-release), or MuJoCo (docs/drive.md).")
@click.option("--gz-release", type=click.Choice(SIM_GZ_RELEASES), default=None, metavar="RELEASE",
              help=f"With --sim gazebo: the Gazebo release to run, one of {', '.join(SIM_GZ_RELEASES)} "
                   f"[default: WORLDGEN_GAZEBO_SETUP's install, else {SIM_GZ_RELEASE}].")
@click.option("--out", type=click.Path(path_type=Path), required=True, metavar="DIR",
              help="Where the run's bag folder is written (DIR/<world id>__<task>__<sim>).")
@click.option("--task", metavar="ID", help="The task to drive [default: the world's first].")
@click.option("--speed", type=click.FloatRange(0, min_open=True), default=None,
              help="Forward speed on the static path, m/s, at most the world's robot's max_speed  [default: that].")
@click.option("--straight", is_flag=True,
              help="Drive spawn -> goal in a straight line instead of the reference path (a test hook: "
                   "it drives into whatever stands between them).")
def drive_command(world: Path, sim: str, out: Path, task: Optional[str], speed: Optional[float], straight: bool,
                  gz_release: Optional[str]) -> None:
    """Drive a world's task in a simulator, record the run as a rosbag2 bag and judge it.

    The robot (worldgen.export.robot in Gazebo, the RL environment's robot in MuJoCo) starts at the
    task's spawn and follows the world's timed path among people, a schedule it works out among movers,
    or else the reference path by pure pursuit, on the simulator's own pose (docs/drive.md); the run
    stops at the goal, the time limit, or when the robot is stuck. The bag holds /clock, /odom, /tf,
    /cmd_vel and /ground_truth and is judged as 'worldgen judge BAG --world WORLD' would judge it.
    Exit status 0 when the run succeeds, 1 when it does not, 2 on bad input. Needs the ros extra.
    """
    from worldgen.ros.deps import require_rosbags
    from worldgen.sim.drive import drive

    require_rosbags()
    outcome = drive(world, out, sim=sim, task=task, straight=straight, speed=speed, gz_release=gz_release)
    run = outcome.run
    collisions = run.get("collisions") or []
    if run.get("success"):
        what = f"reached the goal in {run['time_to_goal']:.2f} s, path {run['path_length']:.2f} m, no contact"
    elif collisions:
        first = collisions[0]
        what = f"collision with {first['entity']} at t = {first['time']:.2f} s (first of {len(collisions)})"
    else:
        stopped = {"stuck": "stuck", "time_limit": "time limit", "goal": "at the goal"}[outcome.ended]
        what = f"{run.get('reason') or 'judged a failure'} (the drive stopped: {stopped})"
    click.echo(f"{sim}: {'PASS' if outcome.passed else 'FAIL'}: {what} ({outcome.sim_seconds:.2f} s simulated, "
               f"{outcome.wall['drive']:.2f} s wall; followed the {_FOLLOWED[outcome.plan]})")
    click.echo(f"bag: {outcome.bag}")
    if not outcome.passed:
        raise click.exceptions.Exit(1)
