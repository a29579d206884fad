"""A thread that yields the cores to the loops: its niceness raised, or SCHED_IDLE.

Why: on two cores the probe's imager (milliseconds of compiled work a frame) takes its turns from
the 1 kHz loops when the cores are full. A higher niceness gives it a smaller share, but the
scheduler (EEVDF) still lets it finish its time slice, about 3 ms, before a loop that wakes gets
the core: a late tick. Under ``SCHED_IDLE`` a waking thread of any other policy preempts it at
once, and it runs only on what the others leave. Only the thread that computes yields, never
one that takes or sends messages: a thread starved while it holds a lock of the middleware's
shared memory would stall every process that writes to it, the robot's among them. Linux keeps
both per thread; neither needs a privilege.
"""
import os
import threading

__all__ = ['yield_thread']


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
