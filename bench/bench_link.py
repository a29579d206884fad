"""The round trip the two site gateways add, against plain UDP between the same two processes.

    .venv/bin/python bench/bench_link.py [--seconds 60] [--runs 1] [--rate 1000] [--threads]
                                         [--answer-every 1] [--json PATH]

Why: a command that crosses to the remote site and the feedback that comes back take the path that
is deployed: DDS in the operator's domain, the operator's gateway, Zenoh over mutual TLS, the
remote gateway, DDS in the remote domain, and back. Its floor is the same two end processes
exchanging the same bytes (a stamped PoseStamped's CDR) as UDP datagrams on the same loopback: what
any transport between them must at least take. Between the two, the same end processes exchange
them over a Zenoh session of their own each, with the gateways' settings (mutual TLS, access
control, the streams' publisher options): what Zenoh itself takes, with no DDS and no gateway
process on the path; the least a gateway in the sites' own processes could add. And over the
gateways as nodes of the sites' own processes (``site_gateway`` composed with a ping node here and
an echo node there, their streams handed over in each process): the path a session deploys, against
the gateways as processes of their own, its baseline. The echo in its site's process is modelled on
the follower: it ticks at 1 kHz, and takes the pings in its tick (``in_tick``), as the follower
takes commands, and this end takes the pongs in its own 1 ms tick, as the leader takes feedback at
each wand pose; beside them, the same ends that take them as the gateways' own 1 ms timers hand
them over (the handover before the follower and the leader took the link in their ticks), and, for
the gateway's share of its site's CPU, the same ticking echo alone, no gateway, nothing to answer
while they are measured (``tick_alone``): each in-process gateway's CPU is its process's less that
one's, in the same round. Taken in ticks, a round trip waits for them whatever carries it; so the
ticking paths are also given over a floor in ticks (``floor_in_tick``): UDP between the ticking
echo alone, which answers the UDP pings in its tick (every ticking echo reads its socket so), and
this end, which takes the pongs at its own 1 ms ticks, with no gateway on the path: what the
gateways add beyond the nodes' ticks. This process sends ``--rate`` numbered pings; an echo
process (``bench_link.py echo``, in the next DDS domain) sends each back at once on every path.
The cases alternate within one invocation, so they share the machine's state; each figure is
given beside its floor, and as the round trip added over it. A ping with no pong 0.5 s after the
window ends is lost. Each gateway's CPU, and the echo's (with its gateway, when it is in the
echo's process), is read from outside (psutil) over the measured window, in % of one core. No
emulated delay: the stage passes messages straight on. With ``--answer-every 10`` the echo
answers every tenth ping only, on every path: the rates a session puts through the remote site's
gateway (1 kHz commands in, 100 Hz feedback out). It ends with issue 27's targets for the deployed
path (``TARGETS``), each held or missed by this run's figures (``verdicts``); the report says the
same of the stored run.
"""
import argparse
import os
import pathlib
import socket
import struct
import sys
import tempfile
import threading
import time

from bench import machine, result_files, ros_domain
from geometry_msgs.msg import PoseStamped
import numpy as np
import psutil
import rclpy
from rclpy.context import Context
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.serialization import serialize_message
from rclpy.task import Future

from haptic_bringup.launcher import gateway_remap, loop_environment
from haptic_bringup.processes import start_child, stop_children
from haptic_bringup.site import loopback_gateway_files, loopback_gateways
from haptic_util import intra_process
from haptic_util.cdr import MessageCodec
from haptic_util.executor import run_nodes
from haptic_util.parameters import declare_parameters, RealtimeParams
from haptic_util.polled_reader import TICK
from haptic_util.qos import LINK_QOS
from haptic_util.tally import Tally
from site_gateway.gateway import GatewayNode, open_session
from site_gateway.routes import site_routes, STREAM
from site_gateway.zenoh_config import Credentials, publisher_options, session_config

PING, PONG = 'bench/ping', 'bench/pong'
POSE_TYPE = 'geometry_msgs/msg/PoseStamped'
DIRECT_PREFIX = 'bench'  # the direct case's Zenoh keys (its sessions reach no gateway's)
CASES = ('floor', 'floor_in_tick', 'zenoh', 'gateways', 'in_process_timer', 'in_process')
# The gateways in the sites' processes: case -> whether the ends take the link in their ticks
# (else the gateways' 1 ms timers hand it over). Both wait for 1 ms ticks.
IN_PROCESS = {'in_process_timer': False, 'in_process': True}
SEQUENCE = struct.Struct('<i')  # the ping's number, in its header's stamp.sec (after CDR's 4)
WARM_UP = 1.0  # [s] of pongs coming back before a window is measured
DRAIN = 0.5  # [s] after a window, for the last pongs
CONNECT_LIMIT = 60.0  # [s] for the path to carry a first pong, on a busy machine
PERCENTILES = (50.0, 99.0, 99.9)
PHASE_SEED = 20261129  # the pings' phases against the echoes' ticks, the same each invocation
SOCKET_BUFFER = 4 << 20  # [bytes] seconds of pings, for a receiver descheduled on a busy machine
# Issue 27's targets for the deployed path: the round trip's p99 added over the floor, and each
# gateway's share of a core in its site's process.
TARGETS = {'added_p99_ms': 2.0, 'gateway_cpu_pct': 10.0}


def ping(sequence: int) -> bytes:
    """Return the CDR bytes of ping ``sequence``: the same on both paths."""
    message = PoseStamped()
    message.header.stamp.sec = sequence
    message.header.frame_id = 'base_link'
    return serialize_message(message)


def answered(sequence: int, every: int) -> bool:
    """Whether the echo answers ping ``sequence``: every ``every``-th."""
    return sequence % every == 0


def answered_bytes(data: bytes, every: int) -> bool:
    """Whether the echo answers the ping ``data`` (its CDR bytes)."""
    return answered(SEQUENCE.unpack_from(data, 4)[0], every)


def udp_socket() -> socket.socket:
    """Return a UDP socket whose receive buffer holds what DDS's deep history would."""
    udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    udp.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, SOCKET_BUFFER)
    return udp


def datagrams(udp: socket.socket):
    """Yield (bytes, sender) of each datagram a non-blocking ``udp`` holds now: a tick's take."""
    while True:
        try:
            yield udp.recvfrom(65536)
        except BlockingIOError:
            return


def direct_session(role: str, certs: pathlib.Path, endpoint: str) -> tuple:
    """Return ``role``'s Zenoh configuration in the direct case, its key to put, its key to take.

    As the gateways' (``site_gateway.zenoh_config``): the remote end listens, the operator's
    dials, each with its site's certificate from ``certs``.
    """
    routes = site_routes(role, [f'{PING}:{POSE_TYPE}'], [f'{PONG}:{POSE_TYPE}'])
    ends = {'listen': (endpoint,) if role == 'remote' else (),
            'connect': (endpoint,) if role == 'operator' else ()}
    config = session_config(routes, **ends, credentials=Credentials.of_site(certs, role),
                            prefix=DIRECT_PREFIX)
    return (config, routes.outgoing[0].key(DIRECT_PREFIX),
            routes.incoming[0].any_role_key(DIRECT_PREFIX))


class Echo(Node):
    """The remote end: each ping, from DDS, UDP or Zenoh, sent straight back the way it came.

    It runs as the loop's nodes do, at their priority (``RealtimeParams``). Zenoh's pings are
    answered in Zenoh's thread, as UDP's are in a thread of their own.
    """

    def __init__(self, udp_port: int, certs: pathlib.Path, endpoint: str) -> None:
        super().__init__('bench_link_echo')
        self._every = self.declare_parameter('answer_every', 1).value
        declare_parameters(self, RealtimeParams)  # after its own: they are not unknown to it
        self._pong = self.create_publisher(PoseStamped, PONG, LINK_QOS)
        self.create_subscription(PoseStamped, PING, self._on_dds, LINK_QOS, raw=True)
        config, pong_key, ping_key = direct_session('remote', certs, endpoint)
        self.session = open_session(config, self.get_name())
        self._zenoh_pong = self.session.declare_publisher(pong_key, **publisher_options(STREAM))
        self._listener = self.session.declare_subscriber(ping_key, self._on_zenoh)
        self._socket = udp_socket()
        self._socket.bind(('127.0.0.1', udp_port))
        threading.Thread(target=self._echo_udp, daemon=True).start()

    def _on_dds(self, data: bytes) -> None:
        if answered_bytes(data, self._every):
            self._pong.publish(data)

    def _on_zenoh(self, sample) -> None:
        data = sample.payload.to_bytes()
        if answered_bytes(data, self._every):
            self._zenoh_pong.put(data)

    def _echo_udp(self) -> None:
        while True:
            data, sender = self._socket.recvfrom(65536)
            if answered_bytes(data, self._every):
                self._socket.sendto(data, sender)


class SiteEcho(Node):
    """The remote end in its site's process: each ping its gateway hands over, handed back.

    It ticks at 1 kHz, as the follower does; with ``in_tick`` it takes the pings in that tick.
    In every tick it also answers the UDP pings its socket (``udp_port``) holds: the ticking
    echo alone is so the floor of the ticking paths (``floor_in_tick``), and every ticking echo
    does the same work but for its gateway's.
    """

    def __init__(self) -> None:
        super().__init__('bench_link_site_echo')
        self._every = self.declare_parameter('answer_every', 1).value
        in_tick = self.declare_parameter('in_tick', True).value
        udp_port = self.declare_parameter('udp_port', 0).value
        declare_parameters(self, RealtimeParams)
        codec = MessageCodec(PoseStamped)
        pong = intra_process.stream_publisher(self, codec, PONG)
        pings = intra_process.link_subscription(
            self, codec, PING,
            lambda values: answered(values[0], self._every) and pong.publish(values),
            refused=Tally(), in_tick=in_tick)
        self._take = pings.take if in_tick else lambda: None
        self._socket = udp_socket()
        self._socket.setblocking(False)
        self._socket.bind(('127.0.0.1', udp_port))
        self.create_timer(TICK, self._tick)

    def _tick(self) -> None:
        self._take()
        for data, sender in datagrams(self._socket):
            if answered_bytes(data, self._every):
                self._socket.sendto(data, sender)


class Pinger:
    """This process's end: pings sent at a rate, each pong's round trip from its send time."""

    def __init__(self, every: int = 1) -> None:
        self.every = every  # the echo answers every ``every``-th ping
        self.sent, self.round_trips = {}, {}  # sequence -> send time; sequence -> round trip
        self._phases = np.random.default_rng(PHASE_SEED)

    def on_pong(self, data: bytes) -> None:
        self.on_sequence(SEQUENCE.unpack_from(data, 4)[0])

    def on_sequence(self, sequence: int) -> None:
        """Take the pong numbered ``sequence``, now."""
        now = time.perf_counter()
        sent = self.sent.get(sequence)
        if sent is not None and sequence not in self.round_trips:
            self.round_trips[sequence] = now - sent

    def run(self, end, rate: float, seconds: float, first: int) -> range:
        """Send pings ``first``... at ``rate`` for ``seconds`` through ``end``; their numbers.

        Between two pings, ``end.wait`` takes the pongs that came (an executor's spin for DDS,
        as the nodes do: a spin in another thread fell behind and its queue stood in the round
        trips, 200 ms at p99). Each second the schedule moves on by a random part of a period,
        so that the phase of its pings against an echo's 1 ms tick is drawn anew: a round trip
        taken in ticks is one tick or two by that phase, fixed for a whole window otherwise (the
        floor in ticks gave p50 1.0 ms in one window and p99 2.0 in the next).
        """
        count = int(rate * seconds)
        start = time.perf_counter()
        for k in range(count):
            if k and k % max(1, int(rate)) == 0:
                start += self._phases.uniform(0.0, 1.0 / rate)
            self.sent[first + k] = time.perf_counter()
            end.send(ping(first + k))
            lag = start + (k + 1) / rate - time.perf_counter()
            if lag > 0:
                end.wait(lag)
        end.wait(DRAIN)
        return range(first, first + count)

    def figures(self, sequences: range) -> dict:
        answered_pings = [s for s in sequences if answered(s, self.every)]
        trips = np.array([self.round_trips[s] for s in answered_pings if s in self.round_trips])
        values = np.percentile(trips, PERCENTILES) * 1e3 if len(trips) else [float('nan')] * 3
        return {**{f'p{q:g}_ms': float(v) for q, v in zip(PERCENTILES, values)},
                'sent': len(answered_pings), 'lost': len(answered_pings) - len(trips)}


class DdsEnd:
    """This process in the operator's domain: pings published, pongs taken raw."""

    def __init__(self, domain: int, pinger: Pinger) -> None:
        self.context = Context()
        rclpy.init(context=self.context, domain_id=domain)
        self.node = Node('bench_link_pinger', context=self.context)
        self.publisher = self.node.create_publisher(PoseStamped, PING, LINK_QOS)
        self.node.create_subscription(PoseStamped, PONG, pinger.on_pong, LINK_QOS, raw=True)
        self.executor = EventsExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.send = self.publisher.publish

    def wait(self, seconds: float) -> None:
        self.executor.spin_until_future_complete(Future(), timeout_sec=seconds)

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


class TickingEnd(DdsEnd):
    """This process as the operator's site: its executor spun in 1 ms ticks, ``_take`` at each.

    ``_take`` (set by each kind of end) takes the pongs that came.
    """

    def wait(self, seconds: float) -> None:
        """Spin for ``seconds``, taking the pongs at each tick (the pings go out at ticks)."""
        deadline = time.perf_counter() + seconds
        while (left := deadline - time.perf_counter()) > 0.0:
            super().wait(min(left, TICK))
            self._take()


class UdpTickEnd(TickingEnd):
    """The floor in ticks: the operator's site with no gateway, its pings and pongs UDP's.

    Its ping node ticks as ``SiteEnd``'s does, and takes the pongs its socket holds at each
    tick: its CPU is that of a ticking site with nothing but the floor's transport.
    """

    def __init__(self, domain: int, port: int, pinger: Pinger) -> None:
        self.context = Context()
        rclpy.init(context=self.context, domain_id=domain)
        self.node = Node('bench_link_udp_pinger', context=self.context)
        self.executor = EventsExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.socket = udp_socket()
        self.socket.bind(('127.0.0.1', 0))
        self.socket.setblocking(False)
        echo = ('127.0.0.1', port)
        self.send = lambda data: self.socket.sendto(data, echo)
        self._pinger = pinger

    def _take(self) -> None:
        for data, _ in datagrams(self.socket):
            self._pinger.on_pong(data)

    def close(self) -> None:
        self.socket.close()
        super().close()


class SiteEnd(TickingEnd):
    """This process as the operator's site: a ping node and the gateway, on one executor.

    The pings are handed to the gateway in the process as a site's nodes hand it their streams
    (their values: decoding each costs this end some microseconds), the pongs handed back: with
    ``in_tick``, taken in this end's 1 ms tick, as the leader takes feedback at each wand pose;
    else as the gateway's 1 ms timer hands them over. The topics are remapped under ``case``:
    this process holds one such end per case, and streams are handed over by topic name in a
    process, so each end's pings reach its own gateway only.
    """

    def __init__(self, domain: int, gateway_params: pathlib.Path, pinger: Pinger,
                 case: str, in_tick: bool) -> None:
        self.context = Context()
        rclpy.init(context=self.context, domain_id=domain, args=[
            '--ros-args', *gateway_remap('operator'), '--params-file', str(gateway_params),
            *[arg for topic in (PING, PONG) for arg in ('-r', f'{topic}:={case}/{topic}')]])
        intra_process.enable()
        self.gateway = GatewayNode(context=self.context)
        self.node = Node('bench_link_site_pinger', context=self.context)
        codec = MessageCodec(PoseStamped)
        publisher = intra_process.stream_publisher(self.node, codec, PING)
        pongs = intra_process.link_subscription(self.node, codec, PONG,
                                                lambda values: pinger.on_sequence(values[0]),
                                                refused=Tally(), in_tick=in_tick)
        self._take = pongs.take if in_tick else lambda: None
        self.executor = EventsExecutor(context=self.context)
        for node in (self.gateway, self.node):
            self.executor.add_node(node)
        self.send = lambda data: publisher.publish(codec.decode(data))

    def close(self) -> None:
        self.gateway.destroy_node()
        intra_process.close()
        super().close()


class UdpEnd:
    """This process's UDP socket to the echo's: the floor."""

    def __init__(self, port: int, pinger: Pinger) -> None:
        self.socket = udp_socket()
        self.socket.bind(('127.0.0.1', 0))
        self.socket.settimeout(0.1)
        self._echo = ('127.0.0.1', port)
        self._pinger, self._running = pinger, True
        self._thread = threading.Thread(target=self._receive, daemon=True)
        self._thread.start()

    def send(self, data: bytes) -> None:
        self.socket.sendto(data, self._echo)  # unconnected: an echo not up yet is no error

    @staticmethod
    def wait(seconds: float) -> None:
        time.sleep(seconds)  # the pongs are taken by the receiving thread

    def _receive(self) -> None:
        while self._running:
            try:
                self._pinger.on_pong(self.socket.recv(65536))
            except socket.timeout:
                continue

    def close(self) -> None:
        self._running = False
        self._thread.join()
        self.socket.close()


class ZenohEnd:
    """This process's own Zenoh session with the echo's: Zenoh alone, no DDS, no gateway."""

    def __init__(self, certs: pathlib.Path, endpoint: str, pinger: Pinger) -> None:
        config, ping_key, pong_key = direct_session('operator', certs, endpoint)
        self.session = open_session(config, 'bench_link')
        self.send = self.session.declare_publisher(ping_key, **publisher_options(STREAM)).put
        self._listener = self.session.declare_subscriber(
            pong_key, lambda sample: pinger.on_pong(sample.payload.to_bytes()))

    @staticmethod
    def wait(seconds: float) -> None:
        time.sleep(seconds)  # the pongs are taken in Zenoh's thread

    def close(self) -> None:
        self.session.close()


def free_port(kind: int) -> int:
    """Return a free loopback port of socket ``kind`` (SOCK_DGRAM, SOCK_STREAM)."""
    with socket.socket(socket.AF_INET, kind) as probe:
        probe.bind(('127.0.0.1', 0))
        return probe.getsockname()[1]


def cpu_seconds(pid: int) -> float:
    times = psutil.Process(pid).cpu_times()
    return times.user + times.system


def thread_cpu_seconds(pid: int) -> dict:
    """Return each thread's CPU time (s) so far, by 'name tid' (the name from /proc)."""
    seconds = {}
    for thread in psutil.Process(pid).threads():
        try:
            name = pathlib.Path(f'/proc/{pid}/task/{thread.id}/comm').read_text().strip()
        except OSError:
            continue  # it ended
        seconds[f'{name} {thread.id}'] = thread.user_time + thread.system_time
    return seconds


def connect(end, pinger: Pinger, first: int) -> int:
    """Ping from ``first`` until pongs come back, then for ``WARM_UP`` s more; the next number.

    Each path is pinged with numbers of its own: a pong of another path's is no sign of this one.
    """
    deadline = time.monotonic() + CONNECT_LIMIT
    start = first
    while not any(s in pinger.round_trips for s in range(start, first)):
        if time.monotonic() > deadline:
            raise RuntimeError('no pong came back: the path is not up')
        first = pinger.run(end, 100.0, 0.1, first).stop
    return pinger.run(end, 1000.0, WARM_UP, first).stop


def measure(case: str, end, pinger: Pinger, args, pids: dict, first: int) -> dict:
    before = {name: cpu_seconds(pid) for name, pid in pids.items()}
    threads_before = {name: thread_cpu_seconds(pid) for name, pid in pids.items()}
    start = time.monotonic()
    sequences = pinger.run(end, args.rate, args.seconds, first)
    wall = time.monotonic() - start - DRAIN
    figures = pinger.figures(sequences)
    figures['cpu_pct'] = {name: 100.0 * (cpu_seconds(pid) - before[name]) / wall
                          for name, pid in pids.items()}
    figures['thread_cpu_pct'] = {
        name: {thread: 100.0 * (seconds - threads_before[name].get(thread, 0.0)) / wall
               for thread, seconds in thread_cpu_seconds(pid).items()}
        for name, pid in pids.items()}
    print(f'{case:<9} ' + ' '.join(f'{figures[f"p{q:g}_ms"]:8.3f}' for q in PERCENTILES)
          + f' {figures["lost"]:5d}/{figures["sent"]:<6d} '
          + ', '.join(f'{name} {cpu:.1f} %' for name, cpu in figures['cpu_pct'].items()),
          flush=True)
    if args.threads:
        for name, threads in figures['thread_cpu_pct'].items():
            busy = sorted(threads.items(), key=lambda item: -item[1])
            print(f'    {name} by thread: ' + ', '.join(
                f'{thread} {cpu:.1f} %' for thread, cpu in busy if cpu >= 0.5), flush=True)
    return figures


def main(argv=None) -> int:
    argv = sys.argv if argv is None else argv
    if len(argv) > 1 and argv[1] == 'echo':
        return run_nodes([lambda: Echo(int(argv[2]), pathlib.Path(argv[3]), argv[4])], argv)
    if len(argv) > 1 and argv[1] in ('site-echo', 'tick-alone'):
        intra_process.enable()
        nodes = [GatewayNode, SiteEcho] if argv[1] == 'site-echo' else [SiteEcho]
        return run_nodes(nodes, argv)
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--seconds', type=float, default=60.0, help='measured window per case')
    parser.add_argument('--runs', type=int, default=1, help='alternated rounds of the cases')
    parser.add_argument('--rate', type=float, default=1000.0, help='[Hz] pings')
    parser.add_argument('--answer-every', type=int, default=1,
                        help='the echo answers every N-th ping (10: the rates of a session at '
                        'the remote gateway); the round trips are of those')
    parser.add_argument('--threads', action='store_true',
                        help="print each process's CPU by thread too (always in --json)")
    ros_domain.add_option(parser, help="the operator's side; the echo's is the next, the two "
                          'pairs of sites with their gateways in them the four after, the '
                          "ticking echo alone the next, and this end of the floor in ticks' the "
                          'next')
    result_files.add_option(parser)
    args = parser.parse_args(argv[1:])
    if args.answer_every < 1:
        parser.error(f'--answer-every must be at least 1, got {args.answer_every}')
    ros_domain.keep_local()
    print(f'machine: {machine.line("ros-jazzy-rclpy", "eclipse-zenoh")}; load average '
          f'{os.getloadavg()[0]:.2f}')
    print(f'{args.rate:g} Hz pings for {args.seconds:g} s per case, {args.runs} alternated '
          f'round(s), every {args.answer_every} answered; round trip in ms; CPU in % of one '
          f'core over the window')
    print(f'{"case":<9} {"p50":>8} {"p99":>8} {"p99.9":>8} {"lost/sent":>12} CPU')
    results = {case: [] for case in CASES}
    with tempfile.TemporaryDirectory() as tmp:
        folder = pathlib.Path(tmp)
        routes = {'to_remote': [f'{PING}:{POSE_TYPE}'], 'to_operator': [f'{PONG}:{POSE_TYPE}']}
        gateways = {child.name.split('_')[0]: child for child in loopback_gateways(
            loopback_gateway_files(folder, routes=routes), sys.executable,
            loop_environment(args.domain_id, folder / 'log'),
            loop_environment(args.domain_id + 1, folder / 'log'))}
        udp_port = free_port(socket.SOCK_DGRAM)
        direct = f'tls/127.0.0.1:{free_port(socket.SOCK_STREAM)}'
        echo = start_child('echo', [sys.executable, __file__, 'echo', str(udp_port),
                                    str(folder / 'certs'), direct, '--ros-args', '-p',
                                    f'bench_link_echo:answer_every:={args.answer_every}'],
                           loop_environment(args.domain_id + 1, folder / 'log'))
        in_process, site_echoes = {}, {}
        for number, (case, in_tick) in enumerate(IN_PROCESS.items()):
            in_process[case] = loopback_gateway_files(folder / case, routes=routes)
            site_echoes[case] = start_child(case, [
                sys.executable, __file__, 'site-echo', '--ros-args', *gateway_remap('remote'),
                '--params-file', str(in_process[case]['remote']), '-p',
                f'bench_link_site_echo:answer_every:={args.answer_every}', '-p',
                f'bench_link_site_echo:in_tick:={in_tick}'],
                loop_environment(args.domain_id + 3 + 2 * number, folder / 'log'))
        tick_port = free_port(socket.SOCK_DGRAM)
        tick_alone = start_child('tick_alone', [sys.executable, __file__, 'tick-alone',
                                                '--ros-args', '-p',
                                                f'bench_link_site_echo:udp_port:={tick_port}',
                                                '-p', 'bench_link_site_echo:answer_every:='
                                                f'{args.answer_every}'],
                                 loop_environment(args.domain_id + 2 + 2 * len(IN_PROCESS),
                                                  folder / 'log'))
        pinger = Pinger(args.answer_every)
        gateway_pids = {f'{role} gateway': child.pid for role, child in gateways.items()}
        # This process: each window's end is its busy one, the others' idle the same in each.
        site = {'operator site': os.getpid()}
        watched = {'floor': {'echo': echo.pid},
                   'floor_in_tick': {'echo': tick_alone.pid, **site},
                   'zenoh': {'echo': echo.pid},
                   'gateways': {**gateway_pids, 'echo': echo.pid},
                   **{case: {'echo': child.pid, 'tick alone': tick_alone.pid, **site}
                      for case, child in site_echoes.items()}}
        ends = {}  # made one by one inside the try: one that fails still stops the others
        try:
            ends['floor'] = UdpEnd(udp_port, pinger)
            ends['floor_in_tick'] = UdpTickEnd(args.domain_id + 3 + 2 * len(IN_PROCESS),
                                               tick_port, pinger)
            ends['zenoh'] = ZenohEnd(folder / 'certs', direct, pinger)
            ends['gateways'] = DdsEnd(args.domain_id, pinger)
            for number, case in enumerate(IN_PROCESS):
                ends[case] = SiteEnd(args.domain_id + 2 + 2 * number, in_process[case]['operator'],
                                     pinger, case, IN_PROCESS[case])
            first = -3_000_000
            for case in CASES:
                first = connect(ends[case], pinger, first)
            first = 0
            for _ in range(args.runs):
                for case in CASES:
                    results[case].append(measure(case, ends[case], pinger, args, watched[case],
                                                 first))
                    first += int(args.rate * args.seconds)
        finally:
            for end in ends.values():
                end.close()
            stop_children([*gateways.values(), echo, *site_echoes.values(), tick_alone])
    summary = summarize(results)
    print(f'load average after: {os.getloadavg()[0]:.2f}')
    paths = {'floor_in_tick': 'UDP between the ticking ends', 'zenoh': 'Zenoh alone',
             'gateways': 'the gateways',
             'in_process_timer': "the gateways in the sites' processes, by timer",
             'in_process': "the gateways in the sites' processes"}
    added = [(what, 'the floor', summary[case]) for case, what in paths.items()]
    added += [(paths[case], 'the floor in ticks', summary['over_floor_in_tick'][case])
              for case in IN_PROCESS]
    for what, floor, over in added:
        print(f'added by {what} over {floor} (median of rounds): ' + ', '.join(
            f'p{q:g} {over["added_ms"][f"p{q:g}"]:.3f} ms ({over["ratio"][f"p{q:g}"]:.1f} x)'
            for q in PERCENTILES) + f'; lost {over["lost"]} of {over["sent"]}')
    print('CPU (median of rounds): ' + ', '.join(
        f'{name} {cpu:.1f} %' for name, cpu in summary['gateway_cpu_pct'].items())
        + '; the echo ' + ', '.join(
            f'{cpu:.1f} % ({case})' for case, cpu in summary['echo_cpu_pct'].items()))
    print("the remote gateway in its site's process, over the ticking echo alone (median of "
          'rounds): ' + ', '.join(f'{cpu:.1f} % ({case})' for case, cpu in
                                  summary['in_process_gateway_cpu_pct'].items()))
    print("the operator's gateway in its site's process (this one), over its floor in ticks "
          '(median of rounds): ' + ', '.join(
              f'{cpu:.1f} % ({case})' for case, cpu in
              summary['operator_in_process_gateway_cpu_pct'].items()))
    print('targets of the deployed path: ' + '; '.join(
        f'{what}: {"held" if holds else "MISSED"}' for what, holds in verdicts(summary)))
    result_files.write(args.json, {'rate_hz': args.rate, 'seconds': args.seconds,
                                   'answer_every': args.answer_every,
                                   'runs': results, 'summary': summary})
    return 0


def summarize(results: dict) -> dict:
    """Return what Zenoh alone and the gateways add over the floor; each gateway's CPU, the echo's.

    The ticking paths are also given over the floor in ticks (``over_floor_in_tick``).

    The remote gateway's CPU in its site's process is the echo's process's less the ticking echo
    alone's, round by round; the operator's, this process's less its own in the floor in ticks
    (its end ticking as much, with UDP for the gateway) in the same round.

    What each adds is the round trip's added quantiles, their ratios, and the loss.
    """
    def median(case: str, key) -> float:
        return float(np.median([key(run) for run in results[case]]))

    def over(case: str, floor: str = 'floor') -> dict:
        keys = {f'p{q:g}': (lambda run, q=q: run[f'p{q:g}_ms']) for q in PERCENTILES}
        return {'added_ms': {q: median(case, key) - median(floor, key)
                             for q, key in keys.items()},
                'ratio': {q: median(case, key) / median(floor, key) for q, key in keys.items()},
                'lost': sum(run['lost'] for run in results[case]),
                'sent': sum(run['sent'] for run in results[case])}
    return {**{case: over(case) for case in CASES[1:]},
            'over_floor_in_tick': {case: over(case, 'floor_in_tick') for case in IN_PROCESS},
            'gateway_cpu_pct': {name: median('gateways', lambda run, n=name: run['cpu_pct'][n])
                                for name in results['gateways'][0]['cpu_pct']
                                if name.endswith('gateway')},
            'echo_cpu_pct': {case: median(case, lambda run: run['cpu_pct']['echo'])
                             for case in CASES},
            'in_process_gateway_cpu_pct': {
                case: median(case, lambda run: run['cpu_pct']['echo']
                             - run['cpu_pct']['tick alone']) for case in IN_PROCESS},
            'operator_in_process_gateway_cpu_pct': {
                case: float(np.median([
                    run['cpu_pct']['operator site'] - floor['cpu_pct']['operator site']
                    for run, floor in zip(results[case], results['floor_in_tick'])]))
                for case in IN_PROCESS},
            'floor_lost': sum(run['lost'] for run in results['floor'])}


def verdicts(summary: dict) -> list:
    """Return issue 27's targets for the deployed path, as (what, holds) pairs."""
    deployed = summary['in_process']
    added = deployed['added_ms']['p99']
    checks = [(f'round trip p99 {added:+.2f} ms over the floor (target <= '
               f'+{TARGETS["added_p99_ms"]:g} ms)', added <= TARGETS['added_p99_ms']),
              (f'{deployed["lost"]} of {deployed["sent"]} lost (target none)',
               deployed['lost'] == 0)]
    for role, key in (('remote', 'in_process_gateway_cpu_pct'),
                      ('operator', 'operator_in_process_gateway_cpu_pct')):
        cpu = summary[key]['in_process']
        checks.append((f'the {role} gateway {cpu:.1f} % of a core (target <= '
                       f'{TARGETS["gateway_cpu_pct"]:g} %)', cpu <= TARGETS['gateway_cpu_pct']))
    return checks


if __name__ == '__main__':
    sys.exit(main())
