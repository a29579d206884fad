"""Launch actions the launch files share: SIGINT heard, processes that fall together, the imager.

Imported by the launch files only: ``launch`` comes with a full ROS 2 install, not with the PyPI
set-up, where the local launcher (``haptic_loop``) does the same.
"""
from functools import partial
import signal
import threading

from launch.actions import (EmitEvent, OpaqueFunction, RegisterEventHandler,
                            SetEnvironmentVariable, TimerAction)
from launch.event_handlers import OnProcessExit
from launch.events import matches_action, Shutdown
from launch.events.process import SignalProcess
from launch.substitutions import EnvironmentVariable
from launch_ros.actions import Node

from haptic_contract.graph import EXECUTABLES, IMAGER, TELEOP_NODES

__all__ = ['AllOrNothing', 'hear_sigint', 'imager', 'local_discovery']

STOP_TIMEOUT = 10.0  # [s] after a failure, the others' time to stop before launch escalates


def local_discovery() -> SetEnvironmentVariable:
    """Keep DDS discovery on this machine, unless the user exported another range."""
    return SetEnvironmentVariable('ROS_AUTOMATIC_DISCOVERY_RANGE', EnvironmentVariable(
        'ROS_AUTOMATIC_DISCOVERY_RANGE', default_value='LOCALHOST'))


def imager(parameters: str, **options) -> Node:
    """Return the remote site's imager: its node in a process of its own, as ``ros2 run``."""
    return Node(package=TELEOP_NODES[IMAGER].package, executable=EXECUTABLES[IMAGER],
                parameters=[parameters], output='screen', **options)


def hear_sigint() -> None:
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


class AllOrNothing:
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
