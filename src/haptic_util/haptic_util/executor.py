"""Spin haptic nodes at 1 kHz, and the Jazzy-style ``main`` every node entry point shares.

rclpy's EventsExecutor is the executor that holds a 1 kHz loop here (the SingleThreadedExecutor
misses it, and the MultiThreadedExecutor collapses to ~100 Hz with several nodes). In the Jazzy
wheel its ``spin()`` never returns and ignores SIGINT, as does ``spin_until_future_complete``
without a timeout. Spinning in short slices hands control back to Python often enough for the
signal handlers (SIGINT → KeyboardInterrupt, SIGTERM → ExternalShutdownException) to run, at no
measurable cost to latency.
"""
import sys
from typing import Callable, Iterable, Optional

import rclpy
from rclpy.executors import Executor, ExternalShutdownException, SingleThreadedExecutor
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.task import Future

__all__ = ['EXECUTORS', 'make_executor', 'spin', 'run_nodes', 'StartupError']

SPIN_SLICE = 0.05  # [s] longest time signals wait to be handled

EXECUTORS = {'events': EventsExecutor, 'single_threaded': SingleThreadedExecutor}


class StartupError(RuntimeError):
    """A node cannot start with its configuration; the message says what to fix."""


def make_executor(kind: str = 'events') -> Executor:
    """Return a new executor of the given kind ('events' or 'single_threaded')."""
    try:
        return EXECUTORS[kind]()
    except KeyError:
        raise ValueError(
            f'executor {kind!r} is not one of {sorted(EXECUTORS)}') from None


def spin(executor: Executor, stop: Optional[Future] = None) -> None:
    """Spin until ``stop`` completes or the context shuts down, in signal-friendly slices."""
    stop = stop or Future()
    while rclpy.ok(context=executor.context) and not stop.done():
        executor.spin_until_future_complete(stop, timeout_sec=SPIN_SLICE)


def run_nodes(factories: Iterable[Callable[[], Node]], args=None, *,
              executor: str = 'events') -> int:
    """Init rclpy, build the nodes, spin them on one executor, and tear down cleanly.

    A node whose configuration is wrong raises ``StartupError`` or ``ValueError`` from its
    constructor: this prints that one line and returns exit code 2, with nothing left running.
    """
    rclpy.init(args=args)
    nodes = []
    try:
        try:
            for factory in factories:
                nodes.append(factory())
        except (StartupError, ValueError) as error:
            print(f'error: {error}', file=sys.stderr, flush=True)
            return 2
        spinner = make_executor(executor)
        for node in nodes:
            spinner.add_node(node)
        spin(spinner)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        for node in nodes:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0
