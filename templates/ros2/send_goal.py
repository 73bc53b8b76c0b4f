#!/usr/bin/env python3
"""Send one worldgen task's goal to nav2 once nav2 is active; wait for the result or the time limit.

Run by the bundle's launch file (written by worldgen, worldgen/export/ros2.py):

    send_goal.py --tasks ros2/tasks.yaml --task task_0 --result RUN.result.yaml [--world-dir D --run K --seed S]
                 --ros-args -p use_sim_time:=true

Waits with nav2_simple_commander's BasicNavigator.waitUntilNav2Active (AMCL active with its initial
pose, bt_navigator active), not a fixed sleep; sends the goal in the map frame; cancels it when the
task's time limit (simulation time, counted from the goal) passes. Writes RESULT (YAML) and exits
0 when nav2 reports the goal reached, 1 when it failed, was canceled or rejected, 2 at the time limit,
3 on bad input.
"""

import argparse
import math
import os
import sys

import yaml

OUTCOME_STATUS = {'succeeded': 0, 'failed': 1, 'canceled': 1, 'rejected': 1, 'time_limit': 2}


def parse(argv):
    """Our arguments, with everything from --ros-args on left to rclpy."""
    ours, ros = (argv[:argv.index('--ros-args')], argv[argv.index('--ros-args'):]) if '--ros-args' in argv else (argv, [])
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--tasks', required=True, help='the bundle tasks.yaml')
    parser.add_argument('--task', required=True, help='a task id of tasks.yaml')
    parser.add_argument('--result', required=True, help='YAML file the outcome is written to')
    parser.add_argument('--world-dir', default='', help='the world folder, recorded in the result')
    parser.add_argument('--run', type=int, default=0)
    parser.add_argument('--seed', type=int, default=0)
    return parser.parse_args(ours), ros


def find_task(spec, task_id):
    for task in spec['tasks']:
        if task['id'] == task_id:
            return task
    raise ValueError(f"task must be one of {', '.join(t['id'] for t in spec['tasks'])}, got {task_id!r}")


def quaternion(yaw):
    """(x, y, z, w) of a rotation by ``yaw`` about +z."""
    return 0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0)


def over_limit(elapsed, limit):
    return limit is not None and elapsed > float(limit)


def write_result(path, data):
    """Written beside and renamed into place: a result file is complete or absent."""
    tmp = path + '.tmp'
    with open(tmp, 'w', encoding='utf-8') as fh:
        yaml.safe_dump(data, fh, sort_keys=True)
    os.replace(tmp, path)


def main(argv=None):
    args, ros_args = parse(sys.argv[1:] if argv is None else argv)
    try:
        with open(args.tasks, encoding='utf-8') as fh:
            spec = yaml.safe_load(fh)
        task = find_task(spec, args.task)
    except (OSError, ValueError, KeyError, TypeError, yaml.YAMLError) as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 3

    import rclpy
    from geometry_msgs.msg import PoseStamped
    from nav2_simple_commander.robot_navigator import BasicNavigator, TaskResult

    rclpy.init(args=['send_goal'] + ros_args)
    navigator = BasicNavigator(node_name='worldgen_send_goal')
    navigator.waitUntilNav2Active()
    goal = PoseStamped()
    goal.header.frame_id = task['goal']['frame_id']
    goal.header.stamp = navigator.get_clock().now().to_msg()
    goal.pose.position.x = float(task['goal']['x'])
    goal.pose.position.y = float(task['goal']['y'])
    qx, qy, qz, qw = quaternion(float(task['goal']['yaw']))
    goal.pose.orientation.x, goal.pose.orientation.y, goal.pose.orientation.z, goal.pose.orientation.w = qx, qy, qz, qw
    start = navigator.get_clock().now()
    outcome = 'rejected'
    if navigator.goToPose(goal):
        outcome = None
        while not navigator.isTaskComplete():  # spins the node for up to 0.1 s a call
            elapsed = (navigator.get_clock().now() - start).nanoseconds / 1e9
            if over_limit(elapsed, task.get('time_limit')):
                navigator.cancelTask()
                outcome = 'time_limit'
                break
        if outcome is None:
            outcome = {TaskResult.SUCCEEDED: 'succeeded', TaskResult.CANCELED: 'canceled'}.get(
                navigator.getResult(), 'failed')
    end = navigator.get_clock().now()
    write_result(args.result, {
        'world_dir': os.path.abspath(args.world_dir) if args.world_dir else '', 'world_id': spec.get('world_id'),
        'task': task['id'], 'run': args.run, 'seed': args.seed, 'outcome': outcome,
        'goal': task['goal'], 'tolerance': task['tolerance'], 'time_limit': task.get('time_limit'),
        'goal_sent_sim_time': start.nanoseconds / 1e9, 'finished_sim_time': end.nanoseconds / 1e9,
    })
    navigator.destroy_node()
    rclpy.shutdown()
    return OUTCOME_STATUS[outcome]


if __name__ == '__main__':
    sys.exit(main())
