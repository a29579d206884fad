"""A thread that yields the cores: its niceness and policy from the kernel, the others' kept."""
import subprocess
import sys

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
SCHED_OTHER, SCHED_IDLE = 0, 5  # Linux's policy numbers


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
    assert kernel.pop(worker) == (niceness, SCHED_IDLE if idle else SCHED_OTHER)
    assert kernel and set(kernel.values()) == {(base, SCHED_OTHER)}  # the main thread's
