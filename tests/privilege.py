"""Processes with and without the right to real-time scheduling (SCHED_FIFO)."""
import contextlib
import os
import shutil
import threading

from haptic_util.parameters import RealtimeParams

__all__ = ['as_real_time_as_the_loop', 'ROOT', 'WITHOUT_REALTIME']

ROOT = os.geteuid() == 0  # CI runs as root
# A command's prefix that takes the right away, as a user without an rtprio limit has it: an
# rtprio limit of 0 (prlimit), and as root no CAP_SYS_NICE either (util-linux's setpriv).
WITHOUT_REALTIME = ('prlimit', '--rtprio=0', *(
    ('setpriv', '--bounding-set', '-sys_nice', '--inh-caps', '-sys_nice') if ROOT else ()))
assert all(shutil.which(tool) for tool in ('prlimit', 'setpriv')), 'util-linux is missing'


@contextlib.contextmanager
def as_real_time_as_the_loop():
    """Run the calling thread as the loop's nodes run by default: under SCHED_FIFO, if they do.

    A peer that floods the loop is the worst case when it is scheduled as the loop is; at normal
    priority, beside nodes that run real-time, it would not flood at all. Where it may not (nor,
    then, may the nodes), it runs as it is.
    """
    thread = threading.get_native_id()
    policy, param = os.sched_getscheduler(thread), os.sched_getparam(thread)
    try:
        if RealtimeParams.thread_priority:
            os.sched_setscheduler(thread, os.SCHED_FIFO,
                                  os.sched_param(RealtimeParams.thread_priority))
    except PermissionError:
        pass
    try:
        yield
    finally:
        os.sched_setscheduler(thread, policy, param)
