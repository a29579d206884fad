"""A process that yields the cores: every thread's niceness and policy, read from the kernel."""
import subprocess
import sys

import pytest

# In a child: this test's own process keeps its priority.
CHILD = """
import os, sys, threading
from haptic_util.priority import yield_cores
started, stop = threading.Event(), threading.Event()
def wait():
    started.set()
    stop.wait()
before = threading.Thread(target=wait)
before.start()
started.wait()
print(yield_cores(7, sys.argv[1] == 'idle'))
started.clear()
after = threading.Thread(target=wait)
after.start()
started.wait()
for task in sorted(os.listdir('/proc/self/task')):
    with open(f'/proc/self/task/{task}/stat') as stat:
        fields = stat.read().rsplit(')', 1)[1].split()
        print(fields[16], fields[38])  # fields 19 and 41: nice, policy
stop.set()
"""
SCHED_OTHER, SCHED_IDLE = 0, 5  # Linux's policy numbers


@pytest.mark.parametrize('idle', [False, True])
def test_every_thread_of_the_process_and_each_it_starts_later_yield(idle):
    base = int(subprocess.run([sys.executable, '-c', 'import os; print(os.nice(0))'],
                              capture_output=True, text=True, check=True).stdout)
    lines = subprocess.run([sys.executable, '-c', CHILD, 'idle' if idle else 'nice'],
                           capture_output=True, text=True, check=True,
                           timeout=60).stdout.splitlines()
    niceness = min(base + 7, 19)
    said = f'SCHED_{"IDLE" if idle else "OTHER"}, niceness {niceness}'
    assert lines[0] == said
    policy = SCHED_IDLE if idle else SCHED_OTHER
    # the main thread, the one started before and the one after
    assert lines[1:] == [f'{niceness} {policy}'] * 3
