"""A process that yields the cores: every thread's niceness raised, read back from the kernel."""
import subprocess
import sys

# In a child: this test's own process keeps its priority.
CHILD = """
import os, threading
from haptic_util.priority import lower_process_priority
started, stop = threading.Event(), threading.Event()
def wait():
    started.set()
    stop.wait()
before = threading.Thread(target=wait)
before.start()
started.wait()
print(lower_process_priority(7))
started.clear()
after = threading.Thread(target=wait)
after.start()
started.wait()
for task in sorted(os.listdir('/proc/self/task')):
    with open(f'/proc/self/task/{task}/stat') as stat:
        print(stat.read().rsplit(')', 1)[1].split()[16])  # field 19: nice
stop.set()
"""


def test_every_thread_of_the_process_and_each_it_starts_later_yield_by_the_niceness():
    base = int(subprocess.run([sys.executable, '-c', 'import os; print(os.nice(0))'],
                              capture_output=True, text=True, check=True).stdout)
    out = subprocess.run([sys.executable, '-c', CHILD], capture_output=True, text=True,
                         check=True, timeout=60).stdout.split()
    expected = min(base + 7, 19)
    assert int(out[0]) == expected
    assert len(out) == 4  # the main thread, the one before and the one after
    assert [int(nice) for nice in out[1:]] == [expected] * 3
