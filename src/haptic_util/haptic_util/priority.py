"""A process that yields the cores: its niceness raised, for every thread it has and will have.

Why: on two cores a process beside the 1 kHz loops (the probe's imager, milliseconds of compiled
work a frame) takes its turns from them when the cores are full. With a higher niceness the
scheduler gives the loops their turn first, and this process what they leave. Linux keeps the
niceness per thread, and a thread starts with its creator's: so each thread the process has (the
DDS middleware's start with ``rclpy.init``) is raised, and those made later inherit it.
"""
import os

__all__ = ['lower_process_priority']


def lower_process_priority(niceness: int) -> int:
    """Add ``niceness`` to each of this process's threads; return the calling thread's after.

    Raising it needs no privilege; a thread that ended meanwhile is skipped.
    """
    if niceness > 0:
        for task in os.listdir('/proc/self/task'):
            try:
                thread = int(task)
                os.setpriority(os.PRIO_PROCESS, thread,
                               os.getpriority(os.PRIO_PROCESS, thread) + niceness)
            except (ProcessLookupError, FileNotFoundError):
                pass
    return os.getpriority(os.PRIO_PROCESS, 0)
