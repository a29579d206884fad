"""The site gateway: one site's DDS domain joined to the other site over one Zenoh session.

    site_gateway --ros-args -p role:=remote -p "listen:=[tls/0.0.0.0:7447]" -p certs:=DIR
    site_gateway --ros-args -p role:=operator -p "connect:=[tls/HOST:7447]" -p certs:=DIR

Each site runs one, in its own DDS domain. What this site publishes of the crossing topics
(``routes``) is read from DDS as serialized CDR bytes, held by the emulated link
(``link_emulator.link``: delay, jitter, loss, reorder, a delay trace; none by default) and put to
Zenoh; what the other site publishes is judged (``inbound``) and published into DDS, the same
bytes. Nothing is converted, so the gateway depends on no message's fields.

The session (``zenoh_config``) is mutual TLS with access control by certificate unless
``insecure`` is set, which logs a warning at every start. It reconnects by itself when the
connection drops and returns; the nodes behind it see a silent link meanwhile, and their own
watchdogs act (the robot holds and retracts, the operator's force goes to zero).

When the other site's gateway stops, it says so (``routes.bye_key``), and this one stops too
(exit 0), so that a site launcher can stop its site cleanly. A connection that is merely lost
says nothing, and the gateway waits for it.

In a site's own process (``haptic_bringup.composed ... site_gateway``, with intra-process
delivery), the 1 kHz streams cross without DDS on this side: what the site's nodes publish is
taken in the process (``haptic_util.intra_process``) and encoded to the same CDR bytes, and what
comes from the other site waits in Zenoh (a ring of the newest, ``HANDOVER_DEPTH``) until it is
judged and handed to the site's nodes, at most ``LINK_INTAKE_RATE`` a second, as the follower
reads the link (``haptic_util.polled_reader``): in the tick of a node that takes the stream in
its own (the follower its commands, the leader its feedback), else by a 1 ms timer of the
gateway's. No Python runs in
Zenoh's threads for a stream then, and a DDS stranger's stream in the site's domain is never
read. What a flood brings beyond the ring between two handovers Zenoh drops
unread, the oldest first, and no count says how much (the counts are of what was judged).
Frames and reliable crossings go through DDS either way. As a process of its own, the gateway
is the baseline ``bench/bench_link.py`` measures it against.

Zenoh's own log (its refusals of a TLS peer: another CA, no certificate, plaintext) goes to
standard output, at ``warn`` unless ``RUST_LOG`` says otherwise. The gateway reports its counts
on ``/diagnostics`` at 1 Hz and logs what it refused, with the role that sent it, once a second.
"""
from dataclasses import dataclass
import functools
import json
import math
import os
import time

from rclpy.exceptions import NameValidationException
from rclpy.expand_topic_name import expand_topic_name
from rclpy.node import Node
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.validate_full_topic_name import validate_full_topic_name
import zenoh

from haptic_contract.graph import absolute, TELEOP_COMMAND, TELEOP_FEEDBACK, TOPIC_TYPES
from haptic_util import intra_process
from haptic_util.callback_errors import log_callback_error
from haptic_util.cdr import MessageCodec
from haptic_util.diagnostics import Diagnostics, OK, Report, WARN
from haptic_util.executor import request_stop, run_nodes, StartupError
from haptic_util.parameters import declare_parameters, parameter, RealtimeParams
from haptic_util.polled_reader import TICK
from haptic_util.qos import FRAME_QOS, LINK_INTAKE_RATE, LINK_QOS
from haptic_util.transport import loopback_udp
from link_emulator.link_stage import emulated_link, ReleaseTimer
from link_emulator.params import LinkStageParams
from link_emulator.relay import message_class, Relay
from site_gateway.inbound import Inbound
from site_gateway.routes import (bye_key, FRAME, other_role, RELIABLE, ROLES, site_routes,
                                 STREAM)
from site_gateway.zenoh_config import (check_endpoints, Credentials, LEASE, publisher_options,
                                       session_config)

__all__ = ['GatewayNode', 'GatewayParams', 'main', 'open_session']

NODE_NAME = 'site_gateway'
DIAGNOSTICS_PERIOD = 1.0  # [s]
ZENOH_LOG = 'warn,zenoh::net::routing::hat::peer=error'
# Zenoh's own threads (its runtimes, read from ZENOH_RUNTIME when the session opens): one
# receiving worker, which also drives the link's socket. By default two receiving workers took
# turns and the socket was driven by a third thread (the accepting one at the listening site,
# the connecting one at the other) that woke them: at 1 kHz each way, about 3300 context
# switches a second in those threads, 800 with this (a quarter of a gateway's CPU samples were
# the kernel switching its threads, perf). Its CPU, alternated with the default in one run,
# three runs at load 12-15: -11 %, -12 %, 0 %. A user's own ZENOH_RUNTIME wins.
ZENOH_RUNTIME = '(rx: (worker_threads: 1), net: (handover: rx), acc: (handover: rx))'
INSECURE_WARNING = ('INSECURE: plaintext, no authentication and no access control: anyone who '
                    'reaches this endpoint can read the session and command the robot. Use it '
                    'only on a network you control end to end; mutual TLS is the default.')
# An incoming stream in the site's process: the newest messages Zenoh holds between two
# handovers (as the link's DDS history holds them), and how many a handover takes at most.
HANDOVER_DEPTH = LINK_QOS.depth
HANDOVER_LIMIT = math.ceil(LINK_INTAKE_RATE * TICK)
RELIABLE_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100,
                          reliability=ReliabilityPolicy.RELIABLE)


def _route(topic: str) -> str:
    """Return the route ('topic:type') that carries the graph's ``topic``."""
    return f'{absolute(topic)}:{TOPIC_TYPES[absolute(topic)]}'


# The default routes: the command and the feedback alone. The graph's whole crossing set
# (TO_REMOTE, TO_OPERATOR) would bring its reliable and image topics as defaults too, and a
# gateway given only its own routes, which leave those out, would refuse to start.
TELEOP_TO_REMOTE = (_route(TELEOP_COMMAND),)
TELEOP_TO_OPERATOR = (_route(TELEOP_FEEDBACK),)


@dataclass(frozen=True)
class GatewayParams(LinkStageParams, RealtimeParams):
    """The gateway's parameters (see config/site_gateway.yaml); the link stage is outgoing."""

    role: str = parameter('operator', "this site's role, and the common name of its "
                          'certificate', choices=ROLES)
    listen: tuple[str, ...] = parameter(('',), 'Zenoh endpoints to listen on, e.g. '
                                        "tls/0.0.0.0:7447 (the remote site); [''] for none")
    connect: tuple[str, ...] = parameter(('',), 'Zenoh endpoints to connect to, e.g. '
                                         "tls/remote.example.org:7447 (the operator site); "
                                         "[''] for none")
    certs: str = parameter('', 'folder holding ca.pem, <role>.pem and <role>.key '
                           '(haptic_certs)')
    insecure: bool = parameter(False, 'plaintext tcp/ endpoints, no certificates and no access '
                               'control (logs a warning at every start)')
    verify_name: bool = parameter(True, "check that the listening site's certificate names "
                                  'the host dialled')
    to_remote: tuple[str, ...] = parameter(
        TELEOP_TO_REMOTE, "topics the operator site sends, 'topic:pkg/msg/Type'; [''] for none")
    to_operator: tuple[str, ...] = parameter(
        TELEOP_TO_OPERATOR, "topics the remote site sends, 'topic:pkg/msg/Type'; [''] for none")
    reliable: tuple[str, ...] = parameter(('',), 'topics (of the above) that must arrive: '
                                          "reliable, blocking; [''] for none")
    frames: tuple[str, ...] = parameter(('',), 'topics (of the above) that are images: after '
                                        "the streams, dropped when congested; [''] for none")
    key_prefix: str = parameter('haptic', 'the Zenoh keys of this session start with it')
    lease: float = parameter(LEASE, 'a connection silent this long is closed and opened anew',
                             unit='s', low=0.1, high=60.0)
    max_rate: float = parameter(2000.0, 'most messages a second handed on per incoming topic; '
                                '0 for no limit', unit='Hz', low=0.0)


def _plan(params: GatewayParams, name: str) -> tuple:
    """Return the site's routes and Zenoh configuration; raise StartupError naming the fault."""
    listen = tuple(e.strip() for e in params.listen if e.strip())
    connect = tuple(e.strip() for e in params.connect if e.strip())
    try:
        routes = site_routes(params.role, params.to_remote, params.to_operator, params.reliable,
                             params.frames)
        check_endpoints(listen, connect, insecure=params.insecure)
        credentials = None
        if not params.insecure:
            if not params.certs:
                raise ValueError('parameter certs is empty: give the folder of this site\'s '
                                 'certificate (haptic_certs), or insecure:=true for plaintext')
            credentials = Credentials.of_site(params.certs, params.role)
        config = session_config(routes, listen=listen, connect=connect,
                                credentials=credentials, prefix=params.key_prefix,
                                lease=params.lease, verify_name=params.verify_name)
    except ValueError as error:
        raise StartupError(f'{name}: {error}') from None
    for crossing in (*routes.outgoing, *routes.incoming):
        try:
            validate_full_topic_name(expand_topic_name(crossing.route.topic, name, '/'))
        except (ValueError, NameValidationException) as error:
            raise StartupError(f'{name}: topic {crossing.route.topic!r}: '
                               f'{str(error).splitlines()[0]}') from None
    return routes, config


def open_session(config: dict, name: str) -> zenoh.Session:
    """Open a gateway's Zenoh session, with its runtime and log; raise StartupError if it fails."""
    os.environ.setdefault('NO_COLOR', '1')  # Zenoh's log lines, plain in a log file
    os.environ.setdefault('ZENOH_RUNTIME', ZENOH_RUNTIME)
    zenoh.init_log_from_env_or(ZENOH_LOG)
    try:
        return zenoh.open(zenoh.Config.from_json5(json.dumps(config)))
    except zenoh.ZError as error:
        raise StartupError(f'{name}: the Zenoh session did not open: {error}') from None


def _qos(kind: str) -> QoSProfile:
    """Return the QoS of a crossing's kind: reliable for what must arrive, a frame's, a stream's.

    A frame is read and written as its publisher and viewers take it (``FRAME_QOS``): reliable
    (an image is many UDP fragments, and one lost would lose it) yet never blocking, as it
    keeps only the newest.

    A stream is read with the link's history (``LINK_QOS``, 100 deep: 100 ms of a 1 kHz
    stream), as the nodes behind the other gateway read it, and as many as the other gateway's
    admission lets through at once (``inbound.BURST``). Read with the haptic streams' 10, a
    gateway descheduled past 10 ms lost messages at its own read: at load 11, counted hop by
    hop, all 192 of 15000 pings ``bench_link`` lost (none between the gateways, none at its
    echo); read 100 deep, none was lost there. What a gateway then handed Zenoh at once could
    still overflow Zenoh's queue of 16 express messages (dropped, not blocked: 20 of 16000 in
    that run); streams are batched since (``zenoh_config``). Read 1000 deep, the operator's
    gateway once stopped taking commands a few seconds into the attacked session (cause not
    found).
    """
    return {RELIABLE: RELIABLE_QOS, FRAME: FRAME_QOS}.get(kind, LINK_QOS)


class GatewayNode(Node):
    """The gateway's node in its site's domain, and its Zenoh session."""

    def __init__(self, **kwargs) -> None:
        super().__init__(NODE_NAME, **kwargs)
        params = declare_parameters(self, GatewayParams)
        name = self.get_name()
        routes, config = _plan(params, name)
        self._role, self._prefix = params.role, params.key_prefix
        if params.insecure:
            self.get_logger().warn(INSECURE_WARNING)
        direction = 'to_remote' if params.role == 'operator' else 'to_operator'
        self._relay = Relay(emulated_link(params, direction, name),
                            reliable={index for index, crossing in enumerate(routes.outgoing)
                                      if crossing.kind == RELIABLE})
        self._inbound = Inbound(routes.incoming, params.key_prefix, params.max_rate)
        self._peers, self._connections, self._closing = set(), 0, False
        self.session = open_session(config, name)
        self._outgoing = [self.session.declare_publisher(c.key(self._prefix),
                                                         **publisher_options(c.kind))
                          for c in routes.outgoing]
        self._bye = self.session.declare_publisher(bye_key(self._prefix, self._role),
                                                   **publisher_options(RELIABLE))
        # Without an emulated link the stage would hand each message on at once: skip its
        # draws and timer (a third of the gateway's CPU at 1 kHz).
        self._emulated = bool(params.delay or params.jitter or params.loss or params.delay_trace)
        self._passed = 0
        on_message = (ReleaseTimer(self._relay, self, self._put).on_message if self._emulated
                      else self._put_now)
        in_process = intra_process.enabled()
        for index, crossing in enumerate(routes.outgoing):
            self._take(crossing, functools.partial(on_message, index),
                       in_process and crossing.kind == STREAM)
        self._into_dds, self._handovers, self._listeners = {}, [], []
        self._untaken = None  # the handovers no node takes in its tick: known at the first tick
        for index, crossing in enumerate(routes.incoming):
            self._hand_on(index, crossing, in_process and crossing.kind == STREAM)
        self._handover_timer = self.create_timer(TICK, self._hand_over_untaken) \
            if self._handovers else None
        self._listeners.append(self.session.declare_subscriber(
            bye_key(self._prefix, other_role(self._role)), self._on_bye))
        self._links = self.session.info.declare_link_events_listener(self._on_link,
                                                                     history=True)
        self.diagnostics = Diagnostics(self, self.report, DIAGNOSTICS_PERIOD)
        security = 'INSECURE plaintext' if params.insecure else \
            f'mutual TLS as {params.role!r} ({params.certs})'
        trace = f'trace {params.delay_trace}' if params.delay_trace else f'{params.delay:g} s'
        self.get_logger().info(
            f'{params.role} site; listen {list(config["listen"]["endpoints"])}, connect '
            f'{list(config["connect"]["endpoints"])}; {security}; '
            f'out: {[c.topic for c in routes.outgoing]}, in: '
            f'{[c.topic for c in routes.incoming]}; outgoing link: delay {trace}, jitter '
            f'{params.jitter:g} s, loss {params.loss:g}, reorder {params.reorder}')

    def _take(self, crossing, send, in_process: bool) -> None:
        """Take what this site publishes of ``crossing`` to ``send``, as its CDR bytes."""
        msg_type = message_class(crossing.route.type_name)
        if not in_process:
            self.create_subscription(msg_type, crossing.route.topic, send,
                                     _qos(crossing.kind), raw=True)
            return
        codec = MessageCodec(msg_type)
        intra_process.stream_subscription(
            self, codec, crossing.route.topic, lambda values: send(codec.encode(values)),
            refused=self._inbound.refused, qos=_qos(crossing.kind))

    def _hand_on(self, index: int, crossing, in_process: bool) -> None:
        """Hand what the other site publishes of ``crossing`` on: in the process, or into DDS."""
        key = crossing.any_role_key(self._prefix)
        msg_type = message_class(crossing.route.type_name)
        if in_process:
            listener = self.session.declare_subscriber(
                key, zenoh.handlers.RingChannel(HANDOVER_DEPTH))
            publisher = intra_process.stream_publisher(self, MessageCodec(msg_type),
                                                       crossing.route.topic)
            handover = (index, listener, publisher)
            publisher.set_source(functools.partial(self._hand_over, handover))
            self._handovers.append(handover)
        else:
            self._into_dds[index] = self.create_publisher(msg_type, crossing.route.topic,
                                                          _qos(crossing.kind))
            listener = self.session.declare_subscriber(
                key, functools.partial(self._on_sample, index))
        self._listeners.append(listener)

    def _hand_over_untaken(self) -> None:
        """Hand over the streams no node takes in its tick; end when every one is so taken.

        Which are taken is known once the process's nodes are made, before its first tick.
        """
        if self._untaken is None:
            self._untaken = [handover for handover in self._handovers
                             if not handover[2].taken_in_tick]
            if not self._untaken:
                self._handover_timer.cancel()
        for handover in self._untaken:
            self._hand_over(handover)

    def _hand_over(self, handover: tuple) -> None:
        """Judge what Zenoh holds of an incoming stream; hand it to the site's nodes."""
        index, listener, publisher = handover
        now = time.monotonic()
        for _ in range(HANDOVER_LIMIT):
            sample = listener.try_recv()
            if sample is None:
                break
            verdict = self._inbound.judge(now, index, str(sample.key_expr),
                                          sample.payload.to_bytes())
            if verdict.deliver:
                publisher.publish(verdict.values)

    def _put(self, route: int, data: bytes) -> None:
        self._outgoing[route].put(data)

    def _put_now(self, route: int, data: bytes) -> None:
        self._passed += 1
        self._outgoing[route].put(data)

    def _on_sample(self, index: int, sample: zenoh.Sample) -> None:
        """Judge a message of the other site's (in Zenoh's thread); hand it on into DDS."""
        try:
            data = sample.payload.to_bytes()
            verdict = self._inbound.judge(time.monotonic(), index, str(sample.key_expr), data)
            if verdict.deliver:
                self._into_dds[index].publish(data)
        except Exception as error:  # a peer's message must never end the gateway
            log_callback_error(error)

    def _on_bye(self, sample: zenoh.Sample) -> None:
        self._closing = True
        self.get_logger().info(f'the {other_role(self._role)} site stopped its gateway: '
                               'stopping this site\'s')
        request_stop()

    def _on_link(self, event: zenoh.LinkEvent) -> None:
        link = event.link
        if event.kind == zenoh.SampleKind.PUT:
            self._peers.add(str(link.zid))
            self._connections += 1
            self.get_logger().info(f'connected: {link.src} -> {link.dst} (peer {link.zid})')
        else:
            self._peers.discard(str(link.zid))
            if not self._closing:
                self.get_logger().warn(f'connection lost: {link.src} -> {link.dst} (peer '
                                       f'{link.zid}); waiting for it to return')

    def report(self) -> Report:
        self._inbound.refused.log_new(self.get_logger().warn)
        values = ({f'out {key}': value for key, value in self._relay.counts().items()}
                  if self._emulated else {'out relayed': self._passed})
        values.update(self._inbound.counts())
        values.update({'peers': len(self._peers), 'connections': self._connections})
        if not self._peers:
            return Report(WARN, 'no peer connected', values)
        return Report(OK, 'relaying', values)

    def destroy_node(self) -> bool:
        """Say the last report, tell the other site, then close the session."""
        self._closing = True
        self.diagnostics.final()
        try:
            self._bye.put(b'')
            for listener in self._listeners:
                listener.undeclare()
            self.session.close()
        except zenoh.ZError as error:
            self.get_logger().warn(f'closing the Zenoh session: {error}')
        self.get_logger().info(
            f'sent {self._relay.relayed + self._passed} (lost on the emulated link '
            f'{self._relay.link.lost}), '
            f'received {sum(self._inbound.received)}, delivered '
            f'{sum(self._inbound.delivered)}, refused {self._inbound.refused.total()}')
        return super().destroy_node()


def main(args=None) -> int:
    """Run the gateway until SIGINT, SIGTERM or the other site's goodbye (exit 0).

    A bad configuration exits 2. The gateway stands for the network between the sites, so it
    talks to its site over UDP on 127.0.0.1, as a remote peer would (``haptic_util.transport``).
    """
    loopback_udp()
    return run_nodes([GatewayNode], args)


if __name__ == '__main__':
    raise SystemExit(main())
