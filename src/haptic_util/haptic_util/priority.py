"""A process that yields the cores to the loops: for every thread it has and will have.

Why: on two cores a process beside the 1 kHz loops (the probe's imager, milliseconds of compiled
work a frame) takes its turns from them when the cores are full. A higher niceness gives it a
smaller share, but the scheduler (EEVDF) still lets it finish its time slice, about 3 ms, before
a loop that wakes gets the core: a late tick. Under ``SCHED_IDLE`` a waking thread of any other
policy preempts it at once, and it runs only on what the others leave. Linux keeps both per
thread, and a thread starts with its creator's: so each thread the process has (the DDS
middleware's start with ``rclpy.init``) is set, and those made later inherit it. Neither needs a
privilege.
"""
import os

__all__ = ['yield_cores']


def yield_cores(niceness: int, idle: bool) -> str:
    """Add ``niceness`` to each of this process's threads, and with ``idle`` set SCHED_IDLE.

    Returns what the calling thread has then, for the log. A thread that ended meanwhile is
    skipped.
    """
    for task in os.listdir('/proc/self/task'):
        thread = int(task)
        try:
            if niceness > 0:
                os.setpriority(os.PRIO_PROCESS, thread,
                               os.getpriority(os.PRIO_PROCESS, thread) + niceness)
            if idle:
                os.sched_setscheduler(thread, os.SCHED_IDLE, os.sched_param(0))
        except ProcessLookupError:
            pass
    policy = 'SCHED_IDLE' if os.sched_getscheduler(0) == os.SCHED_IDLE else 'SCHED_OTHER'
    return f'{policy}, niceness {os.getpriority(os.PRIO_PROCESS, 0)}'
