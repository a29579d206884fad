"""The haptic loop on a full ROS 2 Jazzy install.

    ros2 launch haptic_bringup haptic_loop.launch.py [scene:=...] [experiment:=...]

Arguments: ``scene:=<path or package://...>``, ``experiment:=cuboid|cylinder|hand|hold|<file>``,
``composed:=false`` (three processes; by default one, whose nodes hand their streams to each
other in it: the layout that fits two cores), ``record:=<bag dir>`` (rosbag2 mcap, with the
project's recorder, as ``haptic_loop --record`` does: inside the loop's process, or with
``composed:=false`` a recorder process that the driver waits for; ``ros2 bag`` is not needed,
and a bag that cannot be written fails the launch), ``params_file:=<yaml>`` (overrides on top of
each package's config/). The local launcher (``haptic_loop``) does the same where launch and
ros2cli are not installed.

DDS discovery stays on this machine (``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``) unless the user
exported another range. The loop is all or nothing: when one of its nodes exits, the launch
stops the others, and exits 1 if that node failed (a misspelt ``experiment``, say).
SIGINT to the launch (Ctrl-C, ``kill -INT``, also twice, also when a script started it in the
background) stops every node cleanly.
"""
import os
import tempfile

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node
import yaml

from haptic_bringup.launch_actions import AllOrNothing, hear_sigint, local_discovery
from haptic_contract.graph import EXECUTABLES, LOOP_RECORDER, NODES as LOOP_NODES
from haptic_util.transport import deep_shared_memory_environment

NODES = tuple((entry.package, EXECUTABLES[name], name) for name, entry in LOOP_NODES.items())


def _config(package: str) -> str:
    return os.path.join(get_package_share_directory(package), 'config', f'{package}.yaml')


def _parameters_of(node: str, values: dict) -> str:
    """Write ``values`` as parameters of ``node`` alone, for a process that holds several nodes.

    (A dict in ``parameters`` reaches every node of the process.)
    """
    with tempfile.NamedTemporaryFile('w', prefix='launch_params_', suffix='.yaml',
                                     delete=False) as out:
        yaml.safe_dump({node: {'ros__parameters': values}}, out)
    return out.name


def _nodes(context):
    scene = LaunchConfiguration('scene').perform(context)
    experiment = LaunchConfiguration('experiment').perform(context)
    user = LaunchConfiguration('params_file').perform(context)
    record = LaunchConfiguration('record').perform(context)
    composed = LaunchConfiguration('composed').perform(context).lower() == 'true'
    overrides = {'scene_file': scene} if scene else {}
    driver_values = {'experiment': experiment} if experiment else {}
    recorder = [_parameters_of(LOOP_RECORDER, {'output': os.path.abspath(record)})] \
        if record else []
    if record and not composed:  # a recorder process must hear every topic before the start
        driver_values['wait_for_recorder'] = True
    extra = [user] if user else []
    loop = AllOrNothing()
    actions = []
    if composed:
        # No name: a name given here would rename all three nodes of the process.
        driver = [_parameters_of('wand_driver', driver_values)] if driver_values else []
        actions += loop.add('composed', Node(
            package='haptic_bringup', executable='composed', output='screen',
            arguments=[name for _, _, name in NODES] + ([LOOP_RECORDER] if record else []),
            parameters=[_config(p) for p, _, _ in NODES] + extra + [overrides] + driver
            + recorder))
    else:
        # Recorded by a process of its own: the writers' shared memory as deep as its reader's.
        env = deep_shared_memory_environment() if record else {}
        for package, executable, name in NODES:
            values = dict(overrides, **driver_values) if name == 'wand_driver' else overrides
            actions += loop.add(name, Node(
                package=package, executable=executable, name=name, output='screen',
                parameters=[_config(package), *extra, values], additional_env=env))
        if record:
            actions += loop.add(LOOP_RECORDER, Node(
                package='haptic_bringup', executable='recorder', output='screen',
                parameters=recorder))
    return actions


def generate_launch_description() -> LaunchDescription:
    hear_sigint()
    return LaunchDescription([
        local_discovery(),
        DeclareLaunchArgument('scene', default_value='',
                              description='scene YAML (default: each package config)'),
        DeclareLaunchArgument('experiment', default_value='',
                              description='cuboid | cylinder | hand | hold | waypoint file'),
        DeclareLaunchArgument('composed', default_value='true',
                              description='run the three nodes in one process (false: three)'),
        DeclareLaunchArgument('record', default_value='',
                              description='record the loop to this rosbag2 directory'),
        DeclareLaunchArgument('params_file', default_value='',
                              description='extra parameters YAML'),
        OpaqueFunction(function=_nodes),
    ])
