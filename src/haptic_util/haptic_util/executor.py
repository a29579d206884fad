"""Spin haptic nodes at 1 kHz, and the Jazzy-style ``main`` every node entry point shares.

rclpy's EventsExecutor is the executor that holds a 1 kHz loop here (the SingleThreadedExecutor
misses it, and the MultiThreadedExecutor collapses to ~100 Hz with several nodes). In the Jazzy
wheel its ``spin()`` never returns and ignores SIGINT, as does ``spin_until_future_complete``
without a timeout. Spinning in short slices hands control back to Python often enough to notice a
stop request, at no measurable cost to latency. A slice first runs every callback that is ready,
and those that become ready meanwhile: under a flood (a peer publishing the loop's input as fast
as it can) it never ended, and the node never saw its SIGINT. So a stop request also completes
the slice's future, which ends it after the callback in progress.

Stopping. SIGINT and SIGTERM only ever *request* a stop. ``ros2 launch`` sends SIGINT to every
node on top of the one its process group already got, so repeats are the same request. The spin
then ends while the context is still valid, nodes are destroyed in order and say their last words
(final counts, a zero wrench), and the process exits 0. Start-up is the exception: a node may
spend seconds compiling its kernels before it spins, so a stop requested then interrupts the
start at once (no rclpy callback runs yet), and the process still exits 0.

The signals are held (blocked) and taken by a thread of their own (``sigwait``), not by a Python
handler: such a handler runs only when the main thread next runs Python, inside whatever that
thread is doing (an rclpy callback, a ``Future``'s lock), and in about one stop in a hundred it
never ran at all: the node spun on, its SIGINTs consumed, nothing pending (py-spy, /proc). A
child of the launcher holds SIGINT from its very first instruction (``hold_stop_signals``, in the
child before it runs Python), so one that comes while it still imports waits for this thread:
before, it raised ``KeyboardInterrupt`` inside some import (a traceback), or, inherited as ignored
from a shell without job control, was lost, and the node then spun forever.

The nodes are destroyed, each telling its peers that its endpoints and its name are gone; the
DDS participant under them is not deleted but left to the process's end, held by a hidden node
without endpoints (``_keep_participants``). rmw_fastrtps deletes a context's participant with its
last node, and first calls Fast DDS's ``set_listener(nullptr)`` with no time limit, which waits
until no discovery callback runs. The Fast DDS 2.14.5 wheel is built without
``pthread_cond_clockwait``: that wait's deadline overflows, and it spins holding the very mutex a
running callback needs to end (Fast-DDS issue 6513). A peer that stops at the same moment runs
such a callback, and the stop hung for good: one group stop in about 80 in the test suite, the
main thread spinning in ``DomainParticipant::set_listener``, a receive thread blocked leaving
``onWriterDiscovery``. Peers drop the participant when its lease runs out (20 s); the process
removes its shared-memory segments itself just before it ends (``shared_memory``).

Once its nodes are destroyed and ROS is shut down (which flushes the logs), the process ends at
once (``os._exit``). The interpreter's own teardown would only collect the objects of numba, scipy
and trimesh: 0.7-3.8 s after the last word on this machine under load, past the 2 s a stopping
session is allowed, and, at load 12, past the 5 s ``ros2 launch`` waits before it escalates to
SIGTERM.

A callback that raises does not end its node: the spin logs the exception once, with its
traceback, counts it, and goes on. Each node decides what a failed callback means for its output
(an invalid state, zero force); the count is in ``callback_errors()`` for its diagnostics.
"""
import _thread
import faulthandler
import gc
import os
import signal
import sys
import threading
from typing import Callable, Iterable, NoReturn, Optional

import rclpy
from rclpy.exceptions import NameValidationException, ParameterException
from rclpy.executors import Executor, ExternalShutdownException, SingleThreadedExecutor
from rclpy.experimental import EventsExecutor
from rclpy.impl.implementation_singleton import rclpy_implementation
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.signals import SignalHandlerOptions
from rclpy.task import Future

from haptic_util import intra_process, shared_memory
from haptic_util.callback_errors import callback_errors, log_callback_error
from haptic_util.priority import run_realtime, THREAD_PRIORITY

__all__ = ['EXECUTORS', 'make_executor', 'spin', 'run_nodes', 'run_process', 'end_process',
           'request_stop', 'hold_stop_signals', 'STOP_SIGNALS', 'callback_errors', 'StartupError']

SPIN_SLICE = 0.05  # [s] longest time signals wait to be handled
SHUTDOWN_TIMEOUT = 1.0  # [s] for the executor to finish a callback in progress
TEARDOWN_LIMIT = 20.0  # [s] for nodes to say their last words and be destroyed
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)

REALTIME_REFUSED = (
    'thread_priority {priority}: real-time scheduling (SCHED_FIFO) is not permitted, so this '
    'process runs at normal priority, and on a busy machine its 1 kHz loop may miss ticks. Give '
    'your user an rtprio limit (README, "Real-time priority"), or set thread_priority:=0 to '
    'run without it and silence this.')
EXECUTORS = {'events': EventsExecutor, 'single_threaded': SingleThreadedExecutor}


class StartupError(RuntimeError):
    """A node cannot start with its configuration; the message says what to fix."""


# What a wrong command line, parameter or parameter file raises while a node starts.
_CONFIGURATION_ERRORS = (StartupError, ValueError, ParameterException, NameValidationException,
                         rclpy_implementation.RCLError)
# Plain flags, not threading.Event: the fallback handler below must not take a lock.
# 'starting' is set while nodes are being built: a signal interrupts that; 'interrupt' asks the
# main thread's handler to.
_flags = {'stop': False, 'starting': False, 'interrupt': False}
_slice = [Future()]  # the spin slice in progress ends when this completes
_keepers: list = []  # nodes holding the DDS participants until the process ends (never destroyed)


def request_stop(*_) -> None:
    """Ask this process's loop to stop cleanly; safe from any callback, and idempotent."""
    _flags['stop'] = True
    _end_slice()


def _end_slice() -> None:
    if not _slice[0].done():
        _slice[0].set_result(None)


def hold_stop_signals(signals=STOP_SIGNALS) -> None:
    """Hold ``signals`` pending in this thread and in every thread it later starts.

    A launcher's ``preexec_fn`` holds SIGINT: its child then holds it from its first
    instruction, through its imports, until its stop-signal thread takes it. SIGTERM stays the
    launcher's escalation, which ends a child that has not yet got that far.
    """
    signal.pthread_sigmask(signal.SIG_BLOCK, signals)


def _stop_by_signal() -> bool:
    """Request a stop; return whether it must interrupt the start in progress (once)."""
    starting = _flags['starting']
    _flags['starting'] = False
    request_stop()
    return starting


def _take_stop_signals() -> None:
    """Turn each held stop signal into a stop request, for as long as the process lives."""
    while True:
        signal.sigwait(STOP_SIGNALS)
        if _stop_by_signal():
            _flags['interrupt'] = True
            _thread.interrupt_main()  # runs _on_signal in the main thread, which is building nodes


def _on_signal(signum, frame) -> None:
    """Interrupt the start on request, or take a stop signal that a thread not holding it got.

    Threads a library started before this process's ``_run`` (numpy's) do not hold the signals
    unless the launcher made the process hold them from its start.
    """
    if _stop_by_signal() or _flags['interrupt']:
        _flags['interrupt'] = False
        raise KeyboardInterrupt  # nodes are still being built: no rclpy callback is running


def make_executor(kind: str = 'events', context: Optional[rclpy.Context] = None) -> Executor:
    """Return a new executor of the given kind ('events' or 'single_threaded').

    One executor serves nodes of several contexts (a process in two DDS domains); ``context``
    is the one whose shutdown ends its spin (None: the default context).
    """
    try:
        return EXECUTORS[kind](context=context)
    except KeyError:
        raise ValueError(
            f'executor {kind!r} is not one of {sorted(EXECUTORS)}') from None


def spin(executor: Executor) -> None:
    """Spin until a stop is requested or the context shuts down.

    An exception raised by a callback is logged once per place it comes from and counted.
    """
    while rclpy.ok(context=executor.context) and not _flags['stop']:
        _slice[0] = Future()
        try:
            executor.spin_until_future_complete(_slice[0], timeout_sec=SPIN_SLICE)
        except (KeyboardInterrupt, ExternalShutdownException):
            raise
        except Exception as error:  # any callback's failure is logged, not fatal
            log_callback_error(error)


def run_nodes(factories: Iterable[Callable[[], Node]], args=None, *,
              executor: str = 'events') -> NoReturn:
    """Init rclpy, build the nodes, spin them on one executor, tear down cleanly and exit.

    A node whose configuration is wrong raises ``StartupError``, ``ValueError`` or an rclpy
    parameter error from its constructor: this prints that one line and exits with code 2,
    with nothing left running. A stop requested at any time exits 0.
    """
    def start(nodes: list, contexts: list) -> None:
        rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
        nodes.extend(factory() for factory in factories)
    return run_process(start, executor=executor)


def run_process(start: Callable[[list, list], None], *, executor: str = 'events') -> NoReturn:
    """Run ``start``'s nodes on one executor until a stop, as ``run_nodes`` does, in any contexts.

    ``start(nodes, contexts)`` inits the contexts it needs and builds the nodes, appending each
    as it is made, so that whatever it made is torn down even when it fails half-way; the
    contexts it leaves empty stand for the default one. Exit codes as ``run_nodes``.
    """
    end_process(_run(start, executor))


def _run(start: Callable[[list, list], None], executor: str) -> int:
    for signum in STOP_SIGNALS:
        signal.signal(signum, _on_signal)
    hold_stop_signals()
    _flags['starting'] = True
    nodes, contexts, spinner = [], [], None
    try:
        threading.Thread(target=_take_stop_signals, name='stop-signals', daemon=True).start()
        start(nodes, contexts)
        _keep_participants(contexts)
        _flags['starting'] = False
        _freeze_what_start_made()
        _run_realtime(nodes)
        spinner = make_executor(executor, contexts[0] if contexts else None)
        for node in nodes:
            spinner.add_node(node)
        spin(spinner)
    except _CONFIGURATION_ERRORS as error:
        print(f'error: {_one_line(error)}', file=sys.stderr, flush=True)
        return 2
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        _flags['starting'] = False
        # A teardown that hangs in rclpy or Fast DDS (seen once in about a hundred stops, busy
        # in Node.destroy_node) ends the process with every thread's traceback, never silently.
        faulthandler.dump_traceback_later(TEARDOWN_LIMIT, exit=True)
        if spinner is not None:  # it lets go of the nodes' entities before they are destroyed
            for node in nodes:
                spinner.remove_node(node)
            spinner.shutdown(timeout_sec=SHUTDOWN_TIMEOUT)
        intra_process.close()  # the nodes go one by one: none hears another's last words
        for node in nodes:
            node.destroy_node()
        for context in contexts or [None]:
            rclpy.try_shutdown(context=context)
        shared_memory.remove_segments_held_by(os.getpid())  # the participants' (kept alive)
        faulthandler.cancel_dump_traceback_later()
        # Should an error escape, Python's own exit follows, where it resets its handlers to the
        # default, and a late repeat would kill the process with SIGINT; an ignored signal it
        # leaves alone.
        for signum in STOP_SIGNALS:
            signal.signal(signum, signal.SIG_IGN)
    return 0


def _run_realtime(nodes: list) -> None:
    """Run the process at the highest ``thread_priority`` its nodes ask for, or say why not.

    Once they are built: a node may spend seconds compiling its kernels first, which at
    real-time priority would hold a core from everything else on the machine.
    """
    asking = [node for node in nodes if node.has_parameter(THREAD_PRIORITY)]
    priority = max((node.get_parameter(THREAD_PRIORITY).value for node in asking), default=0)
    if priority <= 0:
        return
    logger = asking[0].get_logger()
    try:
        logger.info(f'this process runs at {run_realtime(priority)}')
    except PermissionError:
        logger.warn(REALTIME_REFUSED.format(priority=priority))


def _keep_participants(contexts: list) -> None:
    """Hold each context's DDS participant with a hidden node that is never destroyed.

    Destroying the nodes then never deletes the participant, which could hang (see above). The
    node has no endpoint of its own, ignores the command line (no remapped name, no parameters
    file), and lives in a module list: freed, it would delete the participant after all.
    """
    for context in contexts or [None]:
        keeper = Node(f'_participant_of_{os.getpid()}', context=context, enable_rosout=False,
                      start_parameter_services=False, use_global_arguments=False,
                      parameter_overrides=[Parameter('start_type_description_service',
                                                     value=False)])
        for publisher in list(keeper.publishers):  # its parameter events: nothing to say
            keeper.destroy_publisher(publisher)
        _keepers.append(keeper)


def _freeze_what_start_made() -> None:
    """Leave what start-up made out of every later garbage collection.

    Imports, compiled kernels and nodes are some 150 000 objects that live as long as the
    process, and a full collection visited them all: 145-246 ms with the loop's thread stopped,
    under load (a recorder in the process, whose chunk index lives half a second, brought one
    every few seconds). Frozen, a collection visits only what was made since. After start-up
    only: a signal then no longer interrupts, so no finalizer the collection runs is cut short.
    """
    gc.collect()
    gc.freeze()


def end_process(code: int) -> NoReturn:
    """End the process now with ``code``, skipping the interpreter's teardown (see above).

    Only once everything that must be said or written is: ROS shut down, files closed.
    """
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # closed, or a reader that went away
            pass
    os._exit(code)


def _one_line(error: Exception) -> str:
    return ' '.join(str(error).split())
