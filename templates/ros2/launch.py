"""One run of the worldgen world @WORLD_ID@: Gazebo Sim headless, the robot at the task's spawn,
the ros_gz bridge, nav2 with the world's map, a rosbag2 recording, the goal sent once nav2 is active,
and shutdown on the result or the time limit. Written by worldgen (worldgen/export/ros2.py); the
whole loop is in worldgen's docs/ros2.md.

    ros2 launch ros2/launch/@ROS_NAME@.launch.py robot:=/abs/path/robot.sdf task:=@FIRST_TASK@ run:=0 seed:=0 out:=bags

The bag is OUT/<world folder>__<task>__run<run>/ (topics: RECORDED_TOPICS below) and beside it
<same name>.result.yaml (what nav2 answered, when, and which world, task, run and seed it was).
Nothing is killed by name: the run ends with launch's Shutdown, which stops every process it started
(the recorder closes its bag on that signal).
"""

import os
import sys

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
BUNDLE = os.path.dirname(HERE)
WORLD_DIR = os.path.dirname(BUNDLE)
#: The <world name> inside the SDF: Gazebo's world, the /world/<name>/create service ros_gz_sim calls.
WORLD_NAME = '@WORLD_NAME@'
#: The world's folder name, which names the bags.
FOLDER = '@FOLDER@'
#: The SDF Gazebo loads, relative to the world folder.
SDF = '@SDF@'
#: What ros2 bag record keeps: what `worldgen judge` reads.
RECORDED_TOPICS = @TOPICS@

#: (name, default, description) of every launch argument.
ARGUMENTS = (
    ('robot', '', 'URDF or SDF file of the robot, spawned with ros_gz_sim create -file'),
    ('robot_topic', '', 'robot_description topic to spawn from instead of a file (ros_gz_sim create -topic)'),
    ('robot_name', '@ROBOT@', "the robot model's name in Gazebo; the bridge config in ros2/bridge.yaml assumes @ROBOT@"),
    ('robot_state_publisher', 'false', 'true: also start robot_state_publisher with the robot file (a URDF)'),
    ('task', '@FIRST_TASK@', 'the task of ros2/tasks.yaml to run'),
    ('run', '0', "the run's number: names the bag"),
    ('seed', '0', "Gazebo's random seed (gz sim --seed)"),
    ('out', 'bags', 'folder the bag and its result file are written into'),
    ('params_file', '', "full nav2 parameters file the task's overrides are merged over; default nav2_bringup's"),
    ('storage', 'mcap', 'rosbag2 storage plugin: mcap or sqlite3'),
    ('wall_limit', '', 'wall-clock seconds after which the run is shut down whatever happens; '
                       'default 10 x the time limit + 120'),
)


def load_yaml(path):
    with open(path, encoding='utf-8') as fh:
        return yaml.safe_load(fh)


def find_task(spec, task_id):
    """The task ``task_id`` of tasks.yaml; a ValueError naming the ids there are otherwise."""
    for task in spec['tasks']:
        if task['id'] == task_id:
            return task
    ids = ', '.join(t['id'] for t in spec['tasks'])
    raise ValueError(f"task must be one of {ids}, got {task_id!r}")


def merge(base, overrides):
    """``overrides`` deep-merged over ``base`` (mappings merged key by key, anything else replaced)."""
    if not isinstance(base, dict) or not isinstance(overrides, dict):
        return overrides
    out = dict(base)
    for key, value in overrides.items():
        out[key] = merge(base.get(key), value) if key in base else value
    return out


def set_sim_time(tree):
    """use_sim_time true in every ros__parameters block, however deeply nested (the costmaps nest)."""
    if isinstance(tree, dict):
        if isinstance(tree.get('ros__parameters'), dict):
            tree['ros__parameters']['use_sim_time'] = True
        for value in tree.values():
            set_sim_time(value)
    return tree


def merged_params(base, overrides, world_dir):
    """The nav2 parameters a run uses: the overrides over ``base``, the map path made absolute."""
    params = set_sim_time(merge(base or {}, overrides))
    block = params.get('map_server', {}).get('ros__parameters', {})
    if block.get('yaml_filename') and not os.path.isabs(block['yaml_filename']):
        block['yaml_filename'] = os.path.join(world_dir, block['yaml_filename'])
    return params


def bag_name(folder, task_id, run):
    return f'{folder}__{task_id}__run{int(run)}'


def spawn_arguments(task, robot, robot_topic, name):
    """ros_gz_sim create's flags: the robot at the task's spawn pose (x, y, z, roll 0, pitch 0, yaw)."""
    if robot:
        source = ['-file', os.path.abspath(robot)]
    elif robot_topic:
        source = ['-topic', robot_topic]
    else:
        raise ValueError('give robot:=FILE (URDF or SDF) or robot_topic:=TOPIC (a robot_description topic)')
    spawn = task['spawn']
    return ['-world', WORLD_NAME, '-name', name, *source,
            '-x', repr(float(spawn['x'])), '-y', repr(float(spawn['y'])), '-z', repr(float(spawn['z'])),
            '-R', '0.0', '-P', '0.0', '-Y', repr(float(spawn['yaw']))]


def gz_args(sdf_path, seed):
    """gz sim's arguments: run at once (-r), server only (-s), sensors rendered without a display."""
    return f'-r -s --headless-rendering --seed {int(seed)} {sdf_path}'


def wall_limit(task, given):
    if given:
        return float(given)
    limit = task.get('time_limit')
    return 600.0 if limit is None else 10.0 * float(limit) + 120.0


def record_command(bag, storage):
    return ['ros2', 'bag', 'record', '--use-sim-time', '-s', storage, '-o', bag, *RECORDED_TOPICS]


def goal_command(task_id, result_path, run, seed):
    return [sys.executable, os.path.join(BUNDLE, 'send_goal.py'), '--tasks', os.path.join(BUNDLE, 'tasks.yaml'),
            '--task', task_id, '--result', result_path, '--world-dir', WORLD_DIR, '--run', str(int(run)),
            '--seed', str(int(seed)), '--ros-args', '-p', 'use_sim_time:=true']


def _on_spawn_exit(event, context):
    from launch.actions import Shutdown

    return [Shutdown(reason='ros_gz_sim create failed to spawn the robot')] if event.returncode else []


def _setup(context):
    from ament_index_python.packages import get_package_share_directory
    from launch.actions import ExecuteProcess, IncludeLaunchDescription, RegisterEventHandler, Shutdown, TimerAction
    from launch.event_handlers import OnProcessExit
    from launch.launch_description_sources import PythonLaunchDescriptionSource
    from launch_ros.actions import Node

    def arg(name):
        return context.launch_configurations.get(name, '')

    task = find_task(load_yaml(os.path.join(BUNDLE, 'tasks.yaml')), arg('task'))
    out = os.path.abspath(arg('out'))
    os.makedirs(out, exist_ok=True)
    name = bag_name(FOLDER, task['id'], arg('run'))
    bag = os.path.join(out, name)
    if os.path.exists(bag):
        raise RuntimeError(f'{bag} exists already: give another run:= or out:=')
    base = arg('params_file') or os.path.join(get_package_share_directory('nav2_bringup'), 'params', 'nav2_params.yaml')
    params = merged_params(load_yaml(base), load_yaml(os.path.join(BUNDLE, 'nav2', task['id'] + '.yaml')), WORLD_DIR)
    params_path = os.path.join(out, name + '.nav2_params.yaml')
    with open(params_path, 'w', encoding='utf-8') as fh:
        yaml.safe_dump(params, fh, sort_keys=True)

    gazebo = IncludeLaunchDescription(
        PythonLaunchDescriptionSource(os.path.join(get_package_share_directory('ros_gz_sim'), 'launch', 'gz_sim.launch.py')),
        launch_arguments={'gz_args': gz_args(os.path.join(WORLD_DIR, SDF), arg('seed')),
                          'on_exit_shutdown': 'true'}.items())
    spawn = Node(package='ros_gz_sim', executable='create', output='screen',
                 arguments=spawn_arguments(task, arg('robot'), arg('robot_topic'), arg('robot_name')))
    bridge = Node(package='ros_gz_bridge', executable='parameter_bridge', output='screen',
                  parameters=[{'config_file': os.path.join(BUNDLE, 'bridge.yaml'), 'use_sim_time': True}])
    nav2 = IncludeLaunchDescription(
        PythonLaunchDescriptionSource(os.path.join(get_package_share_directory('nav2_bringup'), 'launch', 'bringup_launch.py')),
        launch_arguments={'map': os.path.join(WORLD_DIR, 'map.yaml'), 'params_file': params_path,
                          'use_sim_time': 'true', 'autostart': 'true', 'slam': 'False'}.items())
    record = ExecuteProcess(cmd=record_command(bag, arg('storage')), output='screen')
    goal = ExecuteProcess(cmd=goal_command(task['id'], bag + '.result.yaml', arg('run'), arg('seed')), output='screen')
    actions = [gazebo, spawn, bridge, nav2, record, goal,
               # The run ends when the goal sender exits: on nav2's result or at the task's time limit.
               RegisterEventHandler(OnProcessExit(target_action=goal,
                                                  on_exit=[Shutdown(reason='goal finished or time limit reached')])),
               # A robot that cannot be spawned ends the run at once (create exits non-zero).
               RegisterEventHandler(OnProcessExit(target_action=spawn, on_exit=_on_spawn_exit)),
               # A backstop on the wall clock, for a simulation that stalls and never reaches the limit.
               TimerAction(period=wall_limit(task, arg('wall_limit')),
                           actions=[Shutdown(reason='wall-clock limit reached')])]
    if arg('robot_state_publisher') == 'true' and arg('robot'):
        with open(arg('robot'), encoding='utf-8') as fh:
            description = fh.read()
        actions.append(Node(package='robot_state_publisher', executable='robot_state_publisher', output='screen',
                            parameters=[{'robot_description': description, 'use_sim_time': True}]))
    return actions


def generate_launch_description():
    from launch import LaunchDescription
    from launch.actions import DeclareLaunchArgument, OpaqueFunction

    return LaunchDescription([DeclareLaunchArgument(name, default_value=default, description=text)
                              for name, default, text in ARGUMENTS] + [OpaqueFunction(function=_setup)])
