"""Who gets the cores first: the 1 kHz processes at real-time priority; the imager's work last.

Asked to (``thread_priority``), the 1 kHz processes (the loop's nodes, each site's, the gateways)
run every thread under ``SCHED_FIFO`` (``run_realtime``), as ros2_control's controller manager
runs its update loop: no thread of an ordinary process, a compiler, a browser, the probe's
imager, then delays a tick. It is not the default yet: what then runs at normal priority, the
imager and the tests' stand-in attackers among them, gets only what the loops leave. With
another process keeping one of two cores busy, turning the imager on took the robot's rate to
0.81 of what it was with the imager off at normal scheduling; under ``SCHED_FIFO`` it stayed at
1.02 (``bench/imaging_session.py``). It needs root or an ``rtprio`` limit; without either the
process says so once and runs as before.

The imager's frame thread yields (``yield_thread``). On two cores the probe's imager
(milliseconds of compiled work a frame) takes its turns from the 1 kHz loops when the cores are
full. A higher niceness gives it a smaller share, but the scheduler (EEVDF) still lets it finish
its time slice, about 3 ms, before a loop that wakes gets the core: a late tick. Under
``SCHED_IDLE`` a waking thread of any other policy preempts it at once, and it runs only on what
the others leave. Only the thread that computes yields, never one that takes or sends messages:
a thread starved while it holds a lock of the middleware's shared memory would stall every
process that writes to it, the robot's among them. Linux keeps both per thread; neither needs a
privilege.
"""
import os
import threading

__all__ = ['THREAD_PRIORITY', 'run_realtime', 'yield_thread']

THREAD_PRIORITY = 'thread_priority'  # the parameter by which a node asks for run_realtime


def run_realtime(priority: int) -> str:
    """Put every thread of this process under ``SCHED_FIFO`` at ``priority`` (1-99).

    Threads it starts later inherit it from the thread that starts them. Raises
    PermissionError, changing nothing, when the process may not (neither root nor an
    ``rtprio`` limit of at least ``priority``). Returns what the threads then have, for the log.
    """
    tasks = sorted(int(task) for task in os.listdir('/proc/self/task'))
    for task in tasks:
        try:
            os.sched_setscheduler(task, os.SCHED_FIFO, os.sched_param(priority))
        except ProcessLookupError:  # it ended meanwhile
            continue
    return f'SCHED_FIFO, priority {priority}, {len(tasks)} threads'


def yield_thread(niceness: int, idle: bool) -> str:
    """Add ``niceness`` to the calling thread's, and with ``idle`` set it SCHED_IDLE.

    Returns what the thread has then, for the log.
    """
    thread = threading.get_native_id()
    if niceness > 0:
        os.setpriority(os.PRIO_PROCESS, thread,
                       os.getpriority(os.PRIO_PROCESS, thread) + niceness)
    if idle:
        os.sched_setscheduler(thread, os.SCHED_IDLE, os.sched_param(0))
    policy = 'SCHED_IDLE' if os.sched_getscheduler(thread) == os.SCHED_IDLE else 'SCHED_OTHER'
    return f'{policy}, niceness {os.getpriority(os.PRIO_PROCESS, thread)}'
