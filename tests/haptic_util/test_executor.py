"""How a node process ends: signals only request a stop, and a raising callback is survived.

Each test runs a real process, since signals and the executor's spin are what is tested.
"""
import os
import signal
import subprocess
import sys
import time

from privilege import ROOT, WITHOUT_REALTIME
import pytest

from haptic_bringup.launcher import loop_environment

RAISES_ONCE = """
import sys
from rclpy.node import Node
from haptic_util.executor import callback_errors, request_stop, run_nodes

class Flaky(Node):
    def __init__(self):
        super().__init__('flaky')
        self.ticks = 0
        self.create_timer(0.01, self.tick)

    def tick(self):
        self.ticks += 1
        if self.ticks in (3, 5, 7):
            raise RuntimeError(f'tick {self.ticks} failed')
        if self.ticks == 20:
            print(f'alive after {callback_errors()} errors', flush=True)
            request_stop()

sys.exit(run_nodes([Flaky]))
"""

SLOW_START = """
import sys, time
from rclpy.node import Node
from haptic_util.executor import run_nodes

class Slow(Node):
    def __init__(self):
        super().__init__('slow')
        print('starting', flush=True)
        deadline = time.monotonic() + 60.0
        while time.monotonic() < deadline:  # a long compile, in Python bytecode
            sum(range(1000))

sys.exit(run_nodes([Slow]))
"""

SPINNING = """
import sys
from rclpy.node import Node
from haptic_util.executor import run_nodes

class Busy(Node):
    def __init__(self):
        super().__init__('busy')
        self.ticks = 0
        self.create_timer(0.001, self.tick)

    def tick(self):
        self.ticks += 1
        if self.ticks == 10:
            print('spinning', flush=True)
        sum(range(200))

    def destroy_node(self):
        sum(range(10**6))  # a slow goodbye, where a second SIGINT used to land
        print('destroyed', flush=True)
        return super().destroy_node()

sys.exit(run_nodes([Busy]))
"""


OVERRUN = """
import sys, time
from rclpy.node import Node
from haptic_util.executor import run_nodes

class Overrun(Node):
    def __init__(self):
        super().__init__('overrun')
        self.ticks = 0
        self.create_timer(0.001, self.tick)

    def tick(self):  # longer than its period: the executor always has a callback ready
        self.ticks += 1
        if self.ticks == 10:
            print('spinning', flush=True)
        deadline = time.monotonic() + 0.002
        while time.monotonic() < deadline:
            pass

sys.exit(run_nodes([Overrun]))
"""

REALTIME = """
import os, sys
from rclpy.node import Node
from haptic_util.executor import request_stop, run_nodes
from haptic_util.parameters import declare_parameters, RealtimeParams

class Loop(Node):  # a 1 kHz node: it asks, by its parameter
    def __init__(self):
        super().__init__('loop')
        declare_parameters(self, RealtimeParams)
        self.create_timer(0.01, self.tick)

    def tick(self):
        for task in sorted(os.listdir('/proc/self/task')):
            print(os.sched_getscheduler(int(task)), os.sched_getparam(int(task)).sched_priority)
        request_stop()

class Other(Node):  # one that does not ask
    def __init__(self):
        super().__init__('other')

sys.exit(run_nodes([Loop, Other], sys.argv))
"""


def start(script: str, tmp_path, *args: str, prefix: tuple = ()) -> subprocess.Popen:
    return subprocess.Popen([*prefix, sys.executable, '-c', script, *args],
                            stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            env=loop_environment(97, tmp_path / 'log'))


def wait_for_line(process: subprocess.Popen, text: str, timeout: float = 60.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        line = process.stdout.readline()
        if text in line:
            return
        assert line or process.poll() is None, f'exited before {text!r}'
    raise TimeoutError(text)


def test_a_callback_that_raises_is_logged_once_per_place_and_the_node_goes_on(tmp_path):
    process = start(RAISES_ONCE, tmp_path)
    out, err = process.communicate(timeout=120)
    assert process.returncode == 0, err
    assert 'alive after 3 errors' in out
    assert err.count('a callback raised') == 1, err
    assert 'RuntimeError: tick 3 failed' in err and 'Traceback' in err


def test_sigint_during_start_up_stops_the_node_at_once_and_cleanly(tmp_path):
    process = start(SLOW_START, tmp_path)
    wait_for_line(process, 'starting')
    sent = time.monotonic()
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=30)
    assert process.returncode == 0, err
    assert time.monotonic() - sent < 10.0, 'the start-up was not interrupted'
    assert 'Traceback' not in err, err


@pytest.mark.parametrize('gap', [0.0, 0.002, 0.2])
def test_repeated_sigints_are_one_clean_stop(tmp_path, gap):
    process = start(SPINNING, tmp_path)
    wait_for_line(process, 'spinning')
    for _ in range(3):
        process.send_signal(signal.SIGINT)
        time.sleep(gap)
    out, err = process.communicate(timeout=30)
    assert process.returncode == 0, err
    assert 'destroyed' in out
    assert 'Traceback' not in err and 'FATAL' not in err, err


def test_a_node_whose_callbacks_never_catch_up_still_stops_at_sigint(tmp_path):
    """A flood of input (a peer publishing as fast as it can, callbacks that overrun their
    period) left the executor's slice always something to run: the node never saw its SIGINT."""
    process = start(OVERRUN, tmp_path)
    try:
        wait_for_line(process, 'spinning')
        process.send_signal(signal.SIGINT)
        _, err = process.communicate(timeout=30)
    finally:
        process.kill()  # one that did not stop would spin on after the test
    assert process.returncode == 0, err


@pytest.mark.skipif(not ROOT, reason='SCHED_FIFO needs root here (CI runs as root)')
@pytest.mark.parametrize('priority', [30, 0])  # 0: the default
def test_a_node_s_thread_priority_puts_its_whole_process_under_sched_fifo(tmp_path, priority):
    process = start(REALTIME, tmp_path, '--ros-args', '-p', f'loop:thread_priority:={priority}')
    out, err = process.communicate(timeout=120)
    assert process.returncode == 0, err
    threads = {tuple(int(v) for v in line.split()) for line in out.splitlines()}
    assert threads == ({(os.SCHED_FIFO, priority)} if priority else {(os.SCHED_OTHER, 0)})
    assert ('this process runs at SCHED_FIFO' in err) == bool(priority), err


def test_a_node_that_may_not_run_real_time_says_why_and_runs_as_before(tmp_path):
    process = start(REALTIME, tmp_path, '--ros-args', '-p', 'loop:thread_priority:=50',
                    prefix=WITHOUT_REALTIME)
    out, err = process.communicate(timeout=120)
    assert process.returncode == 0, err
    assert {tuple(int(v) for v in line.split()) for line in out.splitlines()} == {
        (os.SCHED_OTHER, 0)}
    assert 'thread_priority 50: real-time scheduling (SCHED_FIFO) is not permitted' in err
