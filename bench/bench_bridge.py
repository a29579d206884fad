"""What the link bridge costs: its CPU relaying a 1 kHz PoseStamped each way, against a bare relay.

    .venv/bin/python bench/bench_bridge.py [--seconds 5] [--runs 2] [--rate 1000]

Why: the bridge is one more process on the two cores both sites share (``docs/cpu_budget.md``).
Its floor is the cheapest relay rclpy can be: one process, one domain, raw subscriptions that
publish the same bytes at once. The bridge does that work in two domains, through the emulated
link and its release timer; the ratio of the two says what the two contexts and the link cost.
Each case runs two site processes, each publishing one stream at ``--rate`` (CDR bytes,
stamped) and taking the other's stream back across the relay; the cases alternate within one
invocation, so they share the machine's state. The bridge's release lateness comes from its
``/diagnostics``; each site counts what it sent and what came back (start-up included), so a
case that did not hold the rate shows.
"""
import argparse
import os
import pathlib
import sys
import tempfile
import time

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PoseStamped
import machine
import numpy as np
import psutil
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.serialization import serialize_message

from haptic_bringup.launcher import add_venv_prefix, loop_environment
from haptic_bringup.processes import start_child, stop_children
from haptic_util.cdr import MessageCodec
from haptic_util.executor import run_nodes
from haptic_util.qos import HAPTIC_STREAM_QOS

POSE = MessageCodec(PoseStamped)
POSE_TYPE = 'geometry_msgs/msg/PoseStamped'
WARM_UP = 3.0  # [s] start-up, discovery in both domains, and the delay queue filling
# (name, relay, one-way delay [s]); the relay 'floor' is BareRelay below.
CASES = (('floor', 'floor', 0.0), ('bridge', 'bridge', 0.0), ('bridge 50 ms', 'bridge', 0.05))


class Site(Node):
    """One site: publishes ``out`` at ``rate`` as stamped bytes, counts what comes on ``back``."""

    def __init__(self, out: str, back: str, rate: float, count_file: str):
        super().__init__('bench_site')
        self.publisher = self.create_publisher(PoseStamped, out, HAPTIC_STREAM_QOS)
        message = PoseStamped()
        message.header.frame_id = 'world'
        self.values = list(POSE.decode(serialize_message(message)))
        self.sent, self.received, self.count_file = 0, 0, count_file
        self.create_subscription(PoseStamped, back, self.on_back, HAPTIC_STREAM_QOS, raw=True)
        self.create_timer(1.0 / rate, self.tick)

    def tick(self) -> None:
        self.values[0], self.values[1] = divmod(self.get_clock().now().nanoseconds, 10**9)
        self.publisher.publish(POSE.encode(self.values))
        self.sent += 1

    def on_back(self, data: bytes) -> None:
        self.received += 1

    def destroy_node(self) -> bool:
        pathlib.Path(self.count_file).write_text(f'{self.received} {self.sent}')
        return super().destroy_node()


class BareRelay(Node):
    """The floor: each topic's bytes republished at once on ``<topic>_out``, in one domain."""

    def __init__(self, topics: list):
        super().__init__('bare_relay')
        for topic in topics:
            publisher = self.create_publisher(PoseStamped, f'{topic}_out', HAPTIC_STREAM_QOS)
            self.create_subscription(PoseStamped, topic, publisher.publish, HAPTIC_STREAM_QOS,
                                     raw=True)


def measure(relay: str, delay: float, args, tmp: pathlib.Path) -> dict:
    """Run one case; return the relay's CPU [% of one core], % back at the sites, lateness."""
    operator, remote = args.domain_id, args.domain_id + 1
    script = os.path.abspath(__file__)
    counts = {site: tmp / f'{site}.count' for site in ('operator', 'remote')}
    floor = relay == 'floor'
    sites = {'operator': ('to_remote', 'to_operator_out' if floor else 'to_operator', operator),
             'remote': ('to_operator', 'to_remote_out' if floor else 'to_remote',
                        operator if floor else remote)}
    children = [start_child(site, [sys.executable, script, 'site', out, back, str(args.rate),
                                   str(counts[site]), '--ros-args'],
                            loop_environment(domain, tmp / 'log'))
                for site, (out, back, domain) in sites.items()]
    if floor:
        argv = [sys.executable, script, 'floor', 'to_remote', 'to_operator', '--ros-args']
    else:
        argv = [sys.executable, '-m', 'remote_probe.bridge', '--ros-args',
                '-p', f'operator_domain:={operator}', '-p', f'remote_domain:={remote}',
                '-p', f"to_remote:=['to_remote:{POSE_TYPE}']",
                '-p', f"to_operator:=['to_operator:{POSE_TYPE}']", '-p', f'delay:={delay}']
    children.append(start_child('relay', argv, loop_environment(operator, tmp / 'log')))
    report = Reports(remote) if not floor else None
    try:
        time.sleep(WARM_UP)
        process = psutil.Process(children[-1].pid)
        start, began = sum(process.cpu_times()[:2]), time.monotonic()
        if report:
            report.spin(args.seconds)
        else:
            time.sleep(args.seconds)
        wall = time.monotonic() - began
        cpu = 100.0 * (sum(process.cpu_times()[:2]) - start) / wall
        lateness = report.lateness() if report else ('-', '-')
    finally:
        if report:
            report.close()
        stop_children(children)
    received, sent = np.sum([[int(n) for n in path.read_text().split()]
                             for path in counts.values()], axis=0)
    return {'cpu': cpu, 'back': 100.0 * received / sent, 'lateness': lateness}


class Reports:
    """The bridge's latest /diagnostics in the remote domain."""

    def __init__(self, domain: int) -> None:
        self.context = Context()
        rclpy.init(context=self.context, domain_id=domain)
        self.node = Node('bench_bridge_reports', context=self.context)
        self.values = {}
        self.node.create_subscription(DiagnosticArray, '/diagnostics', self.on_report, 10)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)

    def on_report(self, array: DiagnosticArray) -> None:
        for status in array.status:
            if status.name == '/link_bridge_remote':
                self.values = {value.key: value.value for value in status.values}

    def spin(self, seconds: float) -> None:
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            self.executor.spin_once(timeout_sec=0.1)

    def lateness(self) -> tuple:
        """Return the worse direction's lateness p50 and p99 [ms], as the bridge said them."""
        if not self.values:
            return '?', '?'
        return tuple(max((self.values[f'{direction} lateness_{q}_ms']
                          for direction in ('to_remote', 'to_operator')),
                         key=lambda text: float('inf') if text == '-' else float(text))
                     for q in ('p50', 'p99'))

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


def main(argv=None) -> int:
    argv = sys.argv if argv is None else argv
    if len(argv) > 1 and argv[1] == 'site':
        out, back, rate, count_file = argv[2], argv[3], float(argv[4]), argv[5]
        return run_nodes([lambda: Site(out, back, rate, count_file)], argv)
    if len(argv) > 1 and argv[1] == 'floor':
        return run_nodes([lambda: BareRelay(argv[2:4])], argv)
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--seconds', type=float, default=5.0, help='measured window per case')
    parser.add_argument('--runs', type=int, default=2, help='median over this many rounds')
    parser.add_argument('--rate', type=float, default=1000.0, help='[Hz] each way')
    parser.add_argument('--domain-id', type=int, default=int(os.environ.get('ROS_DOMAIN_ID', 42)),
                        help='the operator site; the remote one is the next')
    args = parser.parse_args(argv[1:])
    add_venv_prefix()
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    print(f'machine: {machine.line("ros-jazzy-rclpy")}; load average {os.getloadavg()[0]:.2f}')
    print(f'one PoseStamped stream each way at {args.rate:g} Hz, {args.seconds:g} s windows, '
          f'median of {args.runs} alternated rounds; CPU of the relay process in % of one core')
    results = {name: [] for name, _, _ in CASES}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.runs):
            for name, relay, delay in CASES:
                results[name].append(measure(relay, delay, args, pathlib.Path(tmp)))
    floor = float(np.median([r['cpu'] for r in results['floor']]))
    print(f'{"relay":<14} {"CPU %":>6} {"x floor":>7} {"% back at the sites":>20} '
          f'{"lateness p50/p99 ms":>20}')
    for name, runs in results.items():
        cpu = float(np.median([r['cpu'] for r in runs]))
        back = ', '.join(f'{r["back"]:.1f}' for r in runs)
        lateness = ', '.join('/'.join(r['lateness']) for r in runs)
        print(f'{name:<14} {cpu:6.1f} {cpu / floor:7.2f} {back:>20} {lateness:>20}', flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
