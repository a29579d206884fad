"""The loop on a machine it cannot keep up on: it degrades, it does not crash or push stale.

The full loop runs (three processes, the wand tapping the cuboid, rendering locally), while a CPU
hog takes both cores and a second subscriber listens to the 1 kHz streams. At every instant the
simulated device pushed (its own record of when its force switched on and off, one servo period
coarse), the newest answer the driver had received by then must be stamped no earlier than the
model's lifetime (10 ms) before: never a force from a stale state. (The driver's record of what
it received is complete; a starved observer outside is not, so it only says what it saw.) The
driver must also say, on ``/diagnostics``, how far behind it fell.
"""
import subprocess
import sys
import time

from diagnostic_msgs.msg import DiagnosticArray
from domains import session_domain_id
from geometry_msgs.msg import WrenchStamped
from loop_client import LoopClient
import numpy as np

from haptic_bringup.launcher import Loop, loop_environment, LoopConfig
from haptic_util.qos import RECORDER_QOS

SECONDS = 6.0
DRAIN = 2.0  # [s] after the load, to take what queued
LIFETIME = 0.010  # [s] model_lifetime, the force node's default
SERVO_PERIOD_NS = 250_000  # the simulated device's default, 4 kHz
HOG = 'while True: pass'
LISTENER = """
import sys
from geometry_msgs.msg import PoseStamped, WrenchStamped
from rclpy.node import Node
from haptic_util.executor import run_nodes
from haptic_util.qos import HAPTIC_STREAM_QOS

class Listener(Node):
    def __init__(self):
        super().__init__('second_subscriber')
        for kind, topic in ((PoseStamped, 'wand/pose'), (WrenchStamped, 'wand/wrench'),
                            (WrenchStamped, 'wand/applied_wrench')):
            self.create_subscription(kind, topic, lambda msg: None, HAPTIC_STREAM_QOS)

sys.exit(run_nodes([Listener]))
"""


def drain(client: LoopClient, seconds: float) -> None:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        client.executor.spin_once(timeout_sec=0.001)


def test_an_overloaded_loop_degrades_without_crashing_or_applying_a_stale_force(tmp_path):
    domain = session_domain_id()
    stats = tmp_path / 'stats.npz'
    config = LoopConfig(experiment='cuboid', domain_id=domain, run_dir=tmp_path / 'launch',
                        overrides={'wand_driver': {'stats_file': str(stats)}})
    env = loop_environment(domain, tmp_path / 'log')
    with Loop(config) as loop:
        client = LoopClient(domain)
        reports, answers = [], []
        client.node.create_subscription(DiagnosticArray, '/diagnostics', reports.append, 10)
        client.node.create_subscription(  # deep, so that a starved client still sees them all
            WrenchStamped, 'wand/wrench', lambda msg: answers.append(
                msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec), RECORDER_QOS)
        load = [subprocess.Popen([sys.executable, '-c', HOG]) for _ in range(2)]
        load.append(subprocess.Popen([sys.executable, '-c', LISTENER], env=env))
        try:
            drain(client, SECONDS)
        finally:
            for process in load:
                process.kill()
                process.wait()
        drain(client, DRAIN)  # what queued while this client was starved
        alive = {child.name: child.returncode for child in loop.children}
        client.close()
    assert all(code is None for code in alive.values()), f'a node died under load: {alive}'
    record = np.load(stats)  # the driver writes it as the loop stops
    arrivals = record['arrival_ns']
    stamps = arrivals - np.round(record['latencies'] * 1e9).astype(np.int64)
    order = np.argsort(arrivals)
    arrivals, newest = arrivals[order], np.maximum.accumulate(stamps[order])
    worst = 0.0
    for start, end in pushing_intervals(record['force_on_ns'], record['force_off_ns'],
                                        arrivals[-1]):
        inside = (arrivals > start) & (arrivals < end)
        for instant in [start, *(arrivals[inside] - 1), end]:  # just before each new answer
            # The device's record is one servo period coarse: a period starting just before an
            # answer came may render it.
            received = np.searchsorted(arrivals, instant + SERVO_PERIOD_NS, side='right')
            age = (instant - newest[received - 1]) * 1e-9 if received else np.inf
            worst = max(worst, age)
    assert worst <= LIFETIME, f'the device pushed on an answer {worst:.4f} s old'
    said = [s for array in reports for s in array.status if s.hardware_id == 'wand_driver']
    assert said and all('recent_rate_hz' in {v.key for v in s.values} for s in said)
    seen = np.array(client.applied)
    print(f'oldest answer the device pushed on: {1e3 * worst:.2f} ms; the observer saw '
          f'{len(answers)} answers and {seen.shape[0]} applied ticks; the driver said: '
          f'{said[-1].message}')


def pushing_intervals(on_ns, off_ns, last_ns: int) -> list:
    """(start, end) ns of each stretch the device's force was on; an open one ends at last_ns,
    the last answer (the device renders nothing once the driver stops reading it)."""
    intervals = []
    for start in np.sort(on_ns):
        later = off_ns[off_ns > start]
        intervals.append((start, later.min() if later.size else max(start, last_ns)))
    return intervals
