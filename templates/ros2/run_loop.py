#!/usr/bin/env python3
"""N worldgen worlds x M runs: one `ros2 launch` of each world's bundle per run, one bag per run.

Written into every world's ros2/ folder by worldgen (worldgen/export/ros2.py); any copy runs any worlds:

    python3 ros2/run_loop.py --runs 10 --robot /abs/path/robot.sdf --out bags WORLD_DIR [WORLD_DIR ...]

Each world folder must hold a bundle (worldgen generate --ros). Runs go one after another (each
starts its own Gazebo and nav2); run k of a world gets seed --seed + k and is named
<world folder>__<task>__run<k> in OUT, so a run whose bag already exists is skipped and an
interrupted loop resumes where it stopped. --tasks all runs every task of a world, else the first.
Then: worldgen judge OUT/*/ --world ... (docs/ros2.md). Exit status 0 when every launch exited 0.
"""

import argparse
import glob
import os
import subprocess
import sys

import yaml


def launch_file(world_dir):
    found = sorted(glob.glob(os.path.join(world_dir, 'ros2', 'launch', '*.launch.py')))
    if len(found) != 1:
        raise ValueError(f'{world_dir} must hold one ros2/launch/*.launch.py (worldgen generate --ros), found {len(found)}')
    return found[0]


def task_ids(world_dir, which):
    with open(os.path.join(world_dir, 'ros2', 'tasks.yaml'), encoding='utf-8') as fh:
        ids = [t['id'] for t in yaml.safe_load(fh)['tasks']]
    return ids if which == 'all' else ids[:1]


def runs(world_dirs, count, robot, robot_topic, out, seed=0, which='first', extra=()):
    """Every run as (bag path, command): worlds in the order given, then tasks, then runs."""
    out = os.path.abspath(out)
    plan = []
    for world_dir in world_dirs:
        world_dir = os.path.abspath(world_dir)
        launch = launch_file(world_dir)
        for task in task_ids(world_dir, which):
            for k in range(count):
                command = ['ros2', 'launch', launch, f'task:={task}', f'run:={k}', f'seed:={seed + k}', f'out:={out}']
                command.append(f'robot:={os.path.abspath(robot)}' if robot else f'robot_topic:={robot_topic}')
                bag = os.path.join(out, f'{os.path.basename(world_dir.rstrip(os.sep))}__{task}__run{k}')
                plan.append((bag, command + list(extra)))
    return plan


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('worlds', nargs='+', metavar='WORLD_DIR')
    parser.add_argument('--runs', type=int, default=1, help='runs per world and task')
    parser.add_argument('--robot', default='', help='URDF or SDF file of the robot')
    parser.add_argument('--robot-topic', default='', help='or a robot_description topic to spawn from')
    parser.add_argument('--out', default='bags', help='folder of the bags')
    parser.add_argument('--seed', type=int, default=0, help='seed of run 0; run k gets seed + k')
    parser.add_argument('--tasks', choices=('first', 'all'), default='first')
    parser.add_argument('--dry-run', action='store_true', help='print the commands, run nothing')
    parser.add_argument('--launch-arg', dest='extra', action='append', default=[], metavar='KEY:=VALUE',
                        help='one more launch argument for every run (repeatable), e.g. storage:=sqlite3')
    args = parser.parse_args(argv)
    if args.runs < 1 or not (args.robot or args.robot_topic):
        parser.error('give --runs >= 1 and --robot FILE or --robot-topic TOPIC')
    try:
        plan = runs(args.worlds, args.runs, args.robot, args.robot_topic, args.out, args.seed, args.tasks, args.extra)
    except (OSError, ValueError, KeyError, TypeError, yaml.YAMLError) as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 2
    failed = 0
    for bag, command in plan:
        if os.path.exists(bag):
            print(f'skip {bag}: recorded already')
            continue
        print(' '.join(command), flush=True)
        if not args.dry_run and subprocess.run(command).returncode != 0:
            failed += 1
    print(f'{len(plan)} runs planned, {failed} launches failed')
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
