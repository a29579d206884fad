"""What one stream costs at 1 kHz: a publisher process and a subscriber process, CPU of each.

    .venv/bin/python bench/stream_cost.py [--seconds 5] [--rate 1000] [--runs 2]

Why: the CPU budget of both sites (``docs/cpu_budget.md``) adds streams one by one, and the
loop's floor stays the bare three-hop chain; so each stream the project adds gets its own line.
Each stream is carried the way the nodes carry it (CDR bytes: ``publish(bytes)``, a raw
subscription and ``haptic_util.cdr`` on both ends) and, for comparison, as message objects (a
plain rclpy node). A pair with the timer and the subscription but nothing published is the
baseline of a process that merely exists at that rate.
"""
import argparse
import os
import pathlib
import sys
import tempfile
import time

from bench import machine, ros_domain
from geometry_msgs.msg import PoseStamped, TwistStamped, WrenchStamped
import numpy as np
import psutil
from rclpy.node import Node
from rclpy.serialization import serialize_message

from haptic_bringup.launcher import loop_environment
from haptic_bringup.processes import start_child, stop_children
from haptic_msgs.msg import CollisionState, ContactModel
from haptic_util.cdr import MessageCodec
from haptic_util.executor import run_nodes
from haptic_util.qos import HAPTIC_STREAM_QOS

STREAMS = {'wand/pose': PoseStamped, 'wand/twist': TwistStamped,
           'collision/state': CollisionState, 'wand/wrench': WrenchStamped,
           'wand/contact_model': ContactModel, 'wand/applied_wrench': WrenchStamped}
WARM_UP = 2.0  # [s] discovery and matching before the window


class StreamPublisher(Node):
    """Publishes one stream at ``rate``, stamped now, as the nodes do (or as message objects)."""

    def __init__(self, topic: str, mode: str, rate: float):
        super().__init__('stream_publisher')
        kind = STREAMS[topic]
        self.publisher = self.create_publisher(kind, topic, HAPTIC_STREAM_QOS)
        self.codec = MessageCodec(kind)
        self.message = kind()
        self.message.header.frame_id = 'world'
        self.values = self.codec.decode(serialize_message(self.message))
        self.mode = mode
        self.create_timer(1.0 / rate, self.tick)

    def tick(self) -> None:
        now = self.get_clock().now().nanoseconds
        if self.mode == 'bytes':
            self.values[0], self.values[1] = divmod(now, 1_000_000_000)
            self.publisher.publish(self.codec.encode(self.values))
        elif self.mode == 'objects':
            self.message.header.stamp.sec, self.message.header.stamp.nanosec = divmod(
                now, 1_000_000_000)
            self.publisher.publish(self.message)


class StreamSubscriber(Node):
    """Takes one stream and reads every field, as the nodes do (or as message objects)."""

    def __init__(self, topic: str, mode: str):
        super().__init__('stream_subscriber')
        kind = STREAMS[topic]
        self.codec = MessageCodec(kind)
        self.received = 0
        raw = mode != 'objects'
        self.create_subscription(kind, topic, self.on_bytes if raw else self.on_message,
                                 HAPTIC_STREAM_QOS, raw=raw)

    def on_bytes(self, data: bytes) -> None:
        self.codec.decode(data)
        self.received += 1

    def on_message(self, message) -> None:
        self.received += 1


def measure(topic: str, mode: str, rate: float, seconds: float, domain_id: int) -> dict:
    """Run one publisher/subscriber pair; return the CPU of each [% of one core]."""
    with tempfile.TemporaryDirectory() as tmp:
        env = loop_environment(domain_id, pathlib.Path(tmp) / 'log')
        script = os.path.abspath(__file__)
        children = [start_child(role, [sys.executable, script, role, topic, mode, str(rate),
                                       '--ros-args'], env)
                    for role in ('publisher', 'subscriber')]
        try:
            time.sleep(WARM_UP)
            processes = {c.name: psutil.Process(c.pid) for c in children}
            start = {name: sum(p.cpu_times()[:2]) for name, p in processes.items()}
            began = time.monotonic()
            time.sleep(seconds)
            wall = time.monotonic() - began
            cpu = {name: 100.0 * (sum(p.cpu_times()[:2]) - start[name]) / wall
                   for name, p in processes.items()}
        finally:
            stop_children(children)
    return cpu


def main(argv=None) -> int:
    argv = sys.argv if argv is None else argv
    if len(argv) > 1 and argv[1] in ('publisher', 'subscriber'):
        topic, mode, rate = argv[2], argv[3], float(argv[4])
        factory = ((lambda: StreamPublisher(topic, mode, rate)) if argv[1] == 'publisher'
                   else (lambda: StreamSubscriber(topic, mode)))
        return run_nodes([factory], argv)
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--seconds', type=float, default=5.0, help='measured window per pair')
    parser.add_argument('--rate', type=float, default=1000.0, help='[Hz]')
    parser.add_argument('--runs', type=int, default=2, help='median over this many pairs')
    ros_domain.add_option(parser)
    args = parser.parse_args(argv[1:])
    ros_domain.keep_local()
    print(f'machine: {machine.line("ros-jazzy-rclpy")}')
    print(f'one publisher and one subscriber process at {args.rate:g} Hz, {args.seconds:g} s '
          f'windows, median of {args.runs}; CPU in % of one core')
    print(f'{"stream":<22} {"carried as":<10} {"publisher":>9} {"subscriber":>10} {"both":>6} '
          f'{"over idle":>9}')
    cases = [('wand/pose', 'idle')]
    cases += [(topic, mode) for topic in STREAMS for mode in ('bytes', 'objects')]
    idle = None
    for topic, mode in cases:
        runs = [measure(topic, mode, args.rate, args.seconds, args.domain_id)
                for _ in range(args.runs)]
        publisher = float(np.median([r['publisher'] for r in runs]))
        subscriber = float(np.median([r['subscriber'] for r in runs]))
        both = publisher + subscriber
        idle = both if idle is None else idle
        label = '(timer, no message)' if mode == 'idle' else topic
        print(f'{label:<22} {mode:<10} {publisher:9.1f} {subscriber:10.1f} {both:6.1f} '
              f'{both - idle:9.1f}', flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
