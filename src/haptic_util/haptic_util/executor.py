"""Spin haptic nodes at 1 kHz, and the Jazzy-style ``main`` every node entry point shares.

rclpy's EventsExecutor is the executor that holds a 1 kHz loop here (the SingleThreadedExecutor
misses it, and the MultiThreadedExecutor collapses to ~100 Hz with several nodes). In the Jazzy
wheel its ``spin()`` never returns and ignores SIGINT, as does ``spin_until_future_complete``
without a timeout. Spinning in short slices hands control back to Python often enough to notice a
stop request, at no measurable cost to latency.

A stop (SIGINT, SIGTERM, or a node calling ``request_stop``) ends the spin while the context is
still valid, so nodes are destroyed in order and can log and publish their last words (final
counts, a zero wrench); only then is rclpy shut down. A second SIGINT exits at once.
"""
import signal
import sys
import threading
from typing import Callable, Iterable, Optional

import rclpy
from rclpy.executors import Executor, ExternalShutdownException, SingleThreadedExecutor
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from rclpy.task import Future

__all__ = ['EXECUTORS', 'make_executor', 'spin', 'run_nodes', 'request_stop', 'StartupError']

SPIN_SLICE = 0.05  # [s] longest time signals wait to be handled

EXECUTORS = {'events': EventsExecutor, 'single_threaded': SingleThreadedExecutor}

_stop_requested = threading.Event()


def request_stop(*_) -> None:
    """Ask this process's loop to stop cleanly (also the SIGINT/SIGTERM handler)."""
    if _stop_requested.is_set() and _ and _[0] == signal.SIGINT:
        raise KeyboardInterrupt
    _stop_requested.set()


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
    """Spin until a stop is requested, ``stop`` completes or the context shuts down."""
    stop = stop or Future()
    while (rclpy.ok(context=executor.context) and not stop.done()
           and not _stop_requested.is_set()):
        executor.spin_until_future_complete(stop, timeout_sec=SPIN_SLICE)


def run_nodes(factories: Iterable[Callable[[], Node]], args=None, *,
              executor: str = 'events') -> int:
    """Init rclpy, build the nodes, spin them on one executor, and tear down cleanly.

    A node whose configuration is wrong raises ``StartupError`` or ``ValueError`` from its
    constructor: this prints that one line and returns exit code 2, with nothing left running.
    """
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, request_stop)
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
