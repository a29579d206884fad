"""The haptic loop on a full ROS 2 Jazzy install.

    ros2 launch haptic_bringup haptic_loop.launch.py [scene:=...] [experiment:=...]

Arguments: ``scene:=<path or package://...>``, ``experiment:=cuboid|cylinder|hand|hold|<file>``,
``composed:=true`` (one process), ``record:=<bag dir>`` (rosbag2 mcap via ``ros2 bag record``),
``params_file:=<yaml>`` (overrides on top of each package's config/). The local launcher
(``haptic_loop``) does the same where launch and ros2cli are not installed.

DDS discovery stays on this machine (``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``) unless the user
exported another range. The loop is all or nothing: when one of its nodes exits, the launch
stops the others, and exits 1 if that node failed (a misspelt ``experiment``, say).
SIGINT to the launch (Ctrl-C, ``kill -INT``, also twice, also when a script started it in the
background) stops every node cleanly.
"""
from functools import partial
import os
import signal
import tempfile
import threading

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import (DeclareLaunchArgument, EmitEvent, ExecuteProcess, OpaqueFunction,
                            RegisterEventHandler, SetEnvironmentVariable, TimerAction)
from launch.event_handlers import OnProcessExit
from launch.events import matches_action, Shutdown
from launch.events.process import SignalProcess
from launch.substitutions import EnvironmentVariable, LaunchConfiguration
from launch_ros.actions import Node
import yaml

from haptic_bringup.params import LOOP_TOPICS

NODES = (('haptic_wand_driver', 'wand_driver', 'wand_driver'),
         ('collision_engine', 'collision_node', 'collision_engine'),
         ('force_renderer', 'force_node', 'force_renderer'))
STOP_TIMEOUT = 10.0  # [s] after a failure, the others' time to stop before launch escalates


def _hear_sigint() -> None:
    """Let SIGINT reach launch's own handling, and do nothing else.

    launch learns of SIGINT through Python's wakeup fd and then stops every process. Python's
    default handler also raises KeyboardInterrupt wherever launch happens to be: two SIGINTs
    2 ms apart left nodes without their SIGINT, or launch hanging, in 3 of 10 runs. And a shell
    without job control starts ``ros2 launch ... &`` with SIGINT ignored, so launch never heard
    ``kill -INT``. A handler that does nothing fixes both; one somebody else set stays.
    """
    if (threading.current_thread() is threading.main_thread()
            and signal.getsignal(signal.SIGINT) in (signal.SIG_IGN, signal.default_int_handler)):
        signal.signal(signal.SIGINT, lambda signum, frame: None)


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


class _AllOrNothing:
    """The loop's nodes stand or fall together: the first one to exit ends the launch.

    A node that ends cleanly (the driver after its ``duration``) shuts the launch down as usual.
    One that fails stops the others with SIGTERM, not launch's SIGINT: they may still be
    importing, where SIGINT prints a KeyboardInterrupt traceback and SIGTERM ends them quietly
    (a node that has started takes either as a request to stop). Once they are gone, the launch
    fails with exit code 1, naming the node that failed.
    """

    def __init__(self):
        self.running = {}  # name -> Node action
        self.failure = None  # what the first failed node's exit means
        self.failed = False  # whether the launch was told

    def add(self, name: str, node: Node) -> list:
        self.running[name] = node
        return [node, RegisterEventHandler(OnProcessExit(target_action=node,
                                                         on_exit=partial(self._exited, name)))]

    def _exited(self, name, event, context):
        del self.running[name]
        if self.failure is None:
            if context.is_shutdown:
                return None
            if event.returncode == 0:
                return [EmitEvent(event=Shutdown(reason=f'{name} finished'))]
            self.failure = (f'{name} exited with code {event.returncode}; the loop cannot run '
                            'without it')
            if self.running:
                return [*(EmitEvent(event=SignalProcess(signal_number=signal.SIGTERM,
                                                        process_matcher=matches_action(node)))
                          for node in self.running.values()),
                        TimerAction(period=STOP_TIMEOUT, actions=[OpaqueFunction(
                            function=lambda context: self._fail())])]
        if not self.running:
            self._fail()
        return None

    def _fail(self):
        if not self.failed:  # once: the backstop and the last exit may both get here
            self.failed = True
            raise RuntimeError(self.failure)  # launch's exit code is 1 after an error in a handler


def _nodes(context):
    scene = LaunchConfiguration('scene').perform(context)
    experiment = LaunchConfiguration('experiment').perform(context)
    user = LaunchConfiguration('params_file').perform(context)
    record = LaunchConfiguration('record').perform(context)
    overrides = {'scene_file': scene} if scene else {}
    driver_overrides = dict(overrides, **({'experiment': experiment} if experiment else {}))
    extra = [user] if user else []
    loop = _AllOrNothing()
    actions = []
    if LaunchConfiguration('composed').perform(context).lower() == 'true':
        # No name: a name given here would rename all three nodes of the process.
        driver = [_parameters_of('wand_driver', {'experiment': experiment})] if experiment else []
        actions += loop.add('composed', Node(
            package='haptic_bringup', executable='composed', output='screen',
            parameters=[_config(p) for p, _, _ in NODES] + extra + [overrides] + driver))
    else:
        for package, executable, name in NODES:
            values = driver_overrides if name == 'wand_driver' else overrides
            actions += loop.add(name, Node(
                package=package, executable=executable, name=name, output='screen',
                parameters=[_config(package), *extra, values]))
    if record:
        actions.append(ExecuteProcess(
            cmd=['ros2', 'bag', 'record', '-s', 'mcap', '-o', record, *LOOP_TOPICS],
            # (ros2 bag starts recording when it sees each topic: the first samples may be lost;
            # the local launcher's recorder holds the session until it hears every topic.)
            output='screen'))
    return actions


def generate_launch_description() -> LaunchDescription:
    _hear_sigint()
    return LaunchDescription([
        SetEnvironmentVariable('ROS_AUTOMATIC_DISCOVERY_RANGE', EnvironmentVariable(
            'ROS_AUTOMATIC_DISCOVERY_RANGE', default_value='LOCALHOST')),
        DeclareLaunchArgument('scene', default_value='',
                              description='scene YAML (default: each package config)'),
        DeclareLaunchArgument('experiment', default_value='',
                              description='cuboid | cylinder | hand | hold | waypoint file'),
        DeclareLaunchArgument('composed', default_value='false',
                              description='run the three nodes in one process'),
        DeclareLaunchArgument('record', default_value='',
                              description='record the loop to this rosbag2 directory'),
        DeclareLaunchArgument('params_file', default_value='',
                              description='extra parameters YAML'),
        OpaqueFunction(function=_nodes),
    ])
