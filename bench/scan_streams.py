"""The model-mediated scan as ``make demo`` runs it, and its 1 kHz streams measured from outside.

Why one module: the benchmarks that change one thing in a telerobotic session (the imager on or
off, the gateways in the sites' processes or apart) compare the same figures of the same scan,
run by run, alternated. Each figure is taken over the scan's press and sweep (``WINDOW`` after
the session's start, ``wand/session_start``): the operator's loop as its driver measures it
(poses a second, the share answered, the round trip's p99: ``stats_file``); the robot's ticks
from the stamps of the ``robot/tcp_pose`` its own process recorded (a second, and the tick's
p99); the commands that reached the remote site and the feedback that reached the operator, a
second (when each site's recorder received them); and the CPU of every process of the session
(``teleop_scan.process_cpu``, % of one core).
"""
import os
import pathlib

from bench.teleop_scan import process_cpu
import numpy as np
from rosbags.highlevel import AnyReader

from haptic_bringup.bag import typestore_with
from haptic_bringup.launcher import Loop, LoopConfig
from haptic_bringup.recorder import custom_definitions
from haptic_bringup.session import bags, read_session_start, read_vectors

__all__ = ['LINK', 'STREAM_FIGURES', 'TARGETS', 'WINDOW', 'rate', 'scan',
           'stream_ratios', 'total_cpu']

LINK = {'delay': 0.05, 'jitter': 0.005, 'loss': 0.01}  # as the demo's scan
WINDOW = (3.0, 15.0)  # [s] after the session's start: the press and the sweep
TARGETS = {'rate': 0.99, 'answered': 0.99, 'p99': 1.1}  # a change against its baseline
STREAM_FIGURES = ('operator_rate_hz', 'operator_answered_percent', 'operator_round_trip_p99_s',
                  'robot_rate_hz', 'robot_tick_p99_s', 'commands_hz', 'feedback_hz')
_STAMPED = {'/wand/pose': 'pose', '/remote/robot/tcp_pose': 'pose'}
_CROSSED = ('/remote/teleop/command', '/teleop/feedback')  # recorded where they arrived


def _in_window(times: np.ndarray, start: float) -> np.ndarray:
    """Return the ``times`` (s) within ``WINDOW`` of a session that started at ``start``."""
    return times[(times >= start + WINDOW[0]) & (times < start + WINDOW[1])]


def rate(times: np.ndarray) -> float:
    """Return how many a second ``times`` (already in the window) are."""
    return len(times) / (WINDOW[1] - WINDOW[0])


def _received(bag: pathlib.Path, topic: str) -> np.ndarray:
    """When the recorder received each message of ``topic`` (s), without decoding it."""
    with AnyReader(bags(bag)) as reader:
        connections = [c for c in reader.connections if c.topic == topic]
        return np.array([t * 1e-9 for _, t, _ in reader.messages(connections=connections)])


def scan(folder: pathlib.Path, domain_id: int, **config) -> tuple:
    """Run one scan in ``folder`` (its bag: ``folder/bag``); return its figures and its start.

    ``config`` is the rest of its ``LoopConfig`` (``overrides`` are merged with the driver's
    ``stats_file``).
    """
    stats = folder / 'loop_stats.npz'
    overrides = {'wand_driver': {'stats_file': str(stats)}, **config.pop('overrides', {})}
    bag = folder / 'bag'
    with Loop(LoopConfig(teleop='model', link=dict(LINK), record=str(bag), domain_id=domain_id,
                         run_dir=folder / 'launch', overrides=overrides, **config)) as loop:
        cpu = process_cpu(loop)
        if loop.wait(60.0) is None:
            raise RuntimeError('the scan did not end')
    typestore = typestore_with(custom_definitions())
    start = read_session_start(bag, typestore)
    robot = _in_window(read_vectors(bag, typestore, _STAMPED, stamped=True)
                       ['/remote/robot/tcp_pose'][0], start)
    received = {topic: _in_window(_received(bag, topic), start) for topic in _CROSSED}
    loop_stats = np.load(stats)
    return {'load': os.getloadavg()[0],
            'operator_rate_hz': float(loop_stats['rate_hz']),
            'operator_answered_percent': float(loop_stats['answered_percent']),
            'operator_round_trip_p99_s': float(loop_stats['latency_p99_s']),
            'robot_rate_hz': rate(robot),
            'robot_tick_p99_s': float(np.percentile(np.diff(robot), 99)),
            'commands_hz': rate(received['/remote/teleop/command']),
            'feedback_hz': rate(received['/teleop/feedback']),
            'cpu_percent': cpu}, start


def stream_ratios(pairs: list) -> tuple:
    """Return each stream figure's median ratio over ``pairs`` (a run, its baseline), and range."""
    ratios, ranges = {}, {}
    for key in STREAM_FIGURES:
        each = [a[key] / b[key] for a, b in pairs]
        ratios[key], ranges[key] = float(np.median(each)), (min(each), max(each))
    return ratios, ranges


def total_cpu(row: dict) -> float:
    """Return the CPU of all the run's processes, % of one core."""
    return sum(row['cpu_percent'].values())
