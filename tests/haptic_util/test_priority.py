"""Who gets the cores first, read from the kernel: a yielding thread, a real-time process."""
import errno
import os
import subprocess
import sys

from privilege import ROOT, WITHOUT_REALTIME
import pytest

# In a child: this test's own process keeps its priority.
CHILD = """
import os, sys, threading
from haptic_util.priority import yield_thread
said, stop = [], threading.Event()
def work():
    said.append(yield_thread(7, sys.argv[1] == 'idle'))
    stop.wait()
worker = threading.Thread(target=work)
worker.start()
while not said:
    pass
print(said[0])
print(worker.native_id)
for task in sorted(os.listdir('/proc/self/task')):
    with open(f'/proc/self/task/{task}/stat') as stat:
        fields = stat.read().rsplit(')', 1)[1].split()
        print(task, fields[16], fields[38])  # fields 19 and 41: nice, policy
stop.set()
"""


@pytest.mark.parametrize('idle', [False, True])
def test_the_thread_that_asks_yields_and_the_others_keep_their_priority(idle):
    base = int(subprocess.run([sys.executable, '-c', 'import os; print(os.nice(0))'],
                              capture_output=True, text=True, check=True).stdout)
    said, worker, *threads = subprocess.run(
        [sys.executable, '-c', CHILD, 'idle' if idle else 'nice'], capture_output=True,
        text=True, check=True, timeout=60).stdout.splitlines()
    niceness = min(base + 7, 19)
    assert said == f'SCHED_{"IDLE" if idle else "OTHER"}, niceness {niceness}'
    kernel = {task: (int(nice), int(policy))
              for task, nice, policy in (line.split() for line in threads)}
    assert kernel.pop(worker) == (niceness, os.SCHED_IDLE if idle else os.SCHED_OTHER)
    assert kernel and set(kernel.values()) == {(base, os.SCHED_OTHER)}  # the main thread's


# In a child, with the right or without it: its threads before, and one it starts after.
REALTIME_CHILD = """
import os, sys, threading
from haptic_util.priority import run_realtime
started = threading.Event()
early = threading.Thread(target=started.wait)
early.start()
try:
    print(run_realtime(50))
except PermissionError as error:
    print('refused', error.errno)
late = threading.Thread(target=started.wait)
late.start()
for task in sorted(os.listdir('/proc/self/task')):
    print(task, os.sched_getscheduler(int(task)), os.sched_getparam(int(task)).sched_priority)
started.set()
"""


def _run_child(prefix: tuple = ()) -> tuple:
    said, *threads = subprocess.run([*prefix, sys.executable, '-c', REALTIME_CHILD],
                                    capture_output=True, text=True, check=True,
                                    timeout=60).stdout.splitlines()
    return said, {tuple(int(v) for v in line.split()[1:]) for line in threads}, len(threads)


@pytest.mark.skipif(not ROOT, reason='SCHED_FIFO needs root here (CI runs as root)')
def test_every_thread_runs_real_time_and_one_started_after_inherits_it():
    said, policies, count = _run_child()
    assert said == 'SCHED_FIFO, priority 50, 2 threads'
    assert count == 3 and policies == {(os.SCHED_FIFO, 50)}


def test_a_process_that_may_not_is_refused_and_keeps_its_scheduling():
    said, policies, count = _run_child(WITHOUT_REALTIME)
    assert said == f'refused {errno.EPERM}'
    assert count == 3 and policies == {(os.SCHED_OTHER, 0)}
