"""The link bridge: one process in the operator's and the remote site's DDS domains.

Why: the two sites of telerobotic ultrasound run on this machine in two DDS domains, so that
nothing crosses between them except through this process, which holds each message for the
emulated link's delay, jitter and loss (``remote_probe.link``; the kernel here has no netem).

How, with the Jazzy wheels (cost in ``bench/bench_bridge.py``):
- one rclpy ``Context`` per domain, a node in each, and both nodes on one EventsExecutor in one
  thread. An EventsExecutor serves nodes of several contexts. Two executors spun in two threads
  held 1 kHz each way too, at the same CPU, but in a trial beside this design their release
  lateness p99 was 2-5 ms against 0.5-1 ms in one thread (the GIL passed back and forth); and
  one thread needs no locks;
- messages cross as serialized CDR bytes (``raw=True`` in, ``publish(bytes)`` out), never
  converted: the bridge knows the types only by name, and forwarding bytes costs about half as
  much CPU as message objects (``../shared/loop-latency.md``);
- each direction's release timer (steady clock) is re-armed for the link's next arrival, rather
  than polling at 1 kHz: a release is then late by the executor's wake-up alone.

The domains are parameters, but a context's domain is fixed when it starts and rclpy reads
parameters only through a node. So the parameters are read first by a node of a short-lived
context in the process's own ``ROS_DOMAIN_ID``, then the two sites' contexts are started.

It stands for the network between the sites, so it talks to them as a remote peer would: over
UDP on 127.0.0.1, never Fast DDS's shared memory (``haptic_util.transport`` says why).
"""
import functools
import math
import time
from typing import Callable

import rclpy
from rclpy.clock import Clock, ClockType
from rclpy.exceptions import NameValidationException
from rclpy.expand_topic_name import expand_topic_name
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from rclpy.validate_full_topic_name import validate_full_topic_name

from haptic_util.diagnostics import Diagnostics, OK, Report, WARN
from haptic_util.executor import run_process, StartupError
from haptic_util.parameters import declare_parameters
from haptic_util.qos import HAPTIC_STREAM_QOS
from haptic_util.transport import loopback_udp
from remote_probe.link import DelayTrace, EmulatedLink, LinkConfig
from remote_probe.params import LinkBridgeParams, LinkStageParams
from remote_probe.relay import check_no_loop, message_class, parse_routes, Relay

__all__ = ['ReleaseTimer', 'emulated_link', 'join_sites', 'main', 'read_parameters']

NODE_NAME = 'link_bridge'
DIAGNOSTICS_PERIOD = 1.0  # [s]
LATE_WARNING = 1e-3  # [s] release lateness p99 above which the bridge itself distorts the link
_STEADY = Clock(clock_type=ClockType.STEADY_TIME)  # the clock time.monotonic() reads


def emulated_link(params: LinkStageParams, direction: str, node_name: str) -> EmulatedLink:
    """Return one direction's emulated link (``to_operator`` draws with ``seed + 1``).

    A bad value or an unreadable trace raises ``StartupError`` naming the node.
    """
    seed = params.seed + (1 if direction == 'to_operator' else 0)
    try:
        config = LinkConfig(params.delay, params.jitter, params.loss, params.reorder, seed)
    except ValueError as error:
        raise StartupError(f'{node_name}: {error}') from None
    try:
        trace = DelayTrace.from_csv(params.delay_trace) if params.delay_trace else None
    except (ValueError, OSError) as error:
        raise StartupError(f'{node_name}: parameter delay_trace: {error}') from None
    return EmulatedLink(config, trace=trace)


class _Plan:
    """Everything the bridge needs, checked before any site's domain is joined."""

    def __init__(self, params: LinkBridgeParams) -> None:
        if params.operator_domain == params.remote_domain:
            raise StartupError(f'{NODE_NAME}: operator_domain and remote_domain are both '
                               f'{params.operator_domain}; the sites need two domains')
        try:
            self.to_remote = parse_routes(params.to_remote, 'to_remote')
            self.to_operator = parse_routes(params.to_operator, 'to_operator')
            check_no_loop(self.to_remote, self.to_operator)
        except ValueError as error:
            raise StartupError(f'{NODE_NAME}: {error}') from None
        for direction, routes in (('to_remote', self.to_remote),
                                  ('to_operator', self.to_operator)):
            for route in routes:
                try:
                    validate_full_topic_name(expand_topic_name(route.topic, NODE_NAME, '/'))
                except (ValueError, NameValidationException) as error:
                    first = str(error).splitlines()[0]
                    raise StartupError(f'{NODE_NAME}: {direction}: topic {route.topic!r}: '
                                       f'{first}') from None
        self.links = {direction: emulated_link(params, direction, NODE_NAME)
                      for direction in ('to_remote', 'to_operator')}


def read_parameters(args=None) -> LinkBridgeParams:
    """Read and check the parameters with a node of a context of their own, then close it."""
    context = rclpy.Context()
    rclpy.init(args=args, context=context, signal_handler_options=SignalHandlerOptions.NO)
    try:
        node = Node(NODE_NAME, context=context, enable_rosout=False,
                    start_parameter_services=False)
        try:
            return declare_parameters(node, LinkBridgeParams)
        finally:
            node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)


class ReleaseTimer:
    """One direction's emulated link in a node: messages in, each out when its time comes.

    The timer (steady clock) is armed for the link's next arrival, rather than polling at
    1 kHz; a message whose time has come on arrival (no delay) goes out at once, through
    ``emit(route, data)``: a DDS publisher here, a Zenoh one in the site gateway.
    """

    def __init__(self, relay: Relay, node: Node, emit: Callable[[int, bytes], None]) -> None:
        self.relay = relay
        self._emit = emit
        self._timer = node.create_timer(1.0, self.on_timer, clock=_STEADY, autostart=False)
        self._armed = None  # [s] the arrival the timer is armed for

    def on_message(self, route: int, data: bytes) -> None:
        self.relay.send(time.monotonic(), route, data)
        self.release()

    def on_timer(self) -> None:
        self._armed = None  # it fired: arm it again, even for the same arrival
        self.release()

    def release(self) -> None:
        now = time.monotonic()
        for route, data in self.relay.release(now):
            self._emit(route, data)
        due = self.relay.next_arrival
        if due == self._armed:
            return
        self._armed = due
        if due is None:
            self._timer.cancel()
            return
        self._timer.timer_period_ns = max(1, math.ceil((due - now) * 1e9))
        self._timer.reset()


def _wire(relay: Relay, routes: tuple, source: Node, destination: Node) -> None:
    """Wire one direction: raw subscriptions at its source, publishers and timer at its end."""
    classes = [message_class(route.type_name) for route in routes]
    publishers = [destination.create_publisher(cls, route.topic, HAPTIC_STREAM_QOS)
                  for cls, route in zip(classes, routes)]
    stage = ReleaseTimer(relay, destination,
                         lambda route, data: publishers[route].publish(data))
    for index, (cls, route) in enumerate(zip(classes, routes)):
        source.create_subscription(cls, route.topic, functools.partial(stage.on_message, index),
                                   HAPTIC_STREAM_QOS, raw=True)


class _SiteNode(Node):
    """The bridge's node in one site's domain, reporting both directions there.

    The operator's says the final counts as it goes (``says_totals``).
    """

    def __init__(self, name: str, context: rclpy.Context, relays: dict, *,
                 says_totals: bool = False) -> None:
        super().__init__(name, context=context)
        self._relays = relays
        self._says_totals = says_totals
        self.diagnostics = Diagnostics(self, self.report, DIAGNOSTICS_PERIOD)

    def report(self) -> Report:
        values, late = {}, []
        for direction, relay in self._relays.items():
            values.update({f'{direction} {key}': value
                           for key, value in relay.counts().items()})
            p99 = relay.lateness()[1]
            if p99 is not None and p99 > LATE_WARNING:
                late.append(f'{direction} released late (p99 {p99 * 1e3:.1f} ms)')
        return Report(WARN if late else OK, '; '.join(late) or 'relaying', values)

    def destroy_node(self) -> bool:
        self.diagnostics.final()
        if self._says_totals:
            self.get_logger().info(', '.join(
                f'{direction}: {relay.relayed} relayed, {relay.link.lost} lost'
                for direction, relay in self._relays.items()))
        return super().destroy_node()


def join_sites(args, nodes: list, contexts: list) -> None:
    """Join both sites' domains and wire both directions (``run_process``'s ``start``)."""
    params = read_parameters(args)
    plan = _Plan(params)
    relays = {direction: Relay(link) for direction, link in plan.links.items()}
    for site, domain in (('operator', params.operator_domain),
                         ('remote', params.remote_domain)):
        context = rclpy.Context()
        rclpy.init(args=args, context=context, domain_id=domain,
                   signal_handler_options=SignalHandlerOptions.NO)
        contexts.append(context)
        nodes.append(_SiteNode(f'{NODE_NAME}_{site}', context, relays,
                               says_totals=site == 'operator'))
    operator, remote = nodes
    # Each direction lives on in its nodes' subscriptions and timer.
    _wire(relays['to_remote'], plan.to_remote, operator, remote)
    _wire(relays['to_operator'], plan.to_operator, remote, operator)
    trace = f'trace {params.delay_trace}' if params.delay_trace else f'{params.delay:g} s'
    operator.get_logger().info(
        f'domain {params.operator_domain} <-> {params.remote_domain}: '
        f'{len(plan.to_remote)} topics to remote, {len(plan.to_operator)} to operator; '
        f'delay {trace}, jitter {params.jitter:g} s, loss {params.loss:g}, '
        f'reorder {params.reorder}')


def main(args=None) -> int:
    """Run the bridge until SIGINT or SIGTERM (exit 0); a bad configuration exits 2."""
    loopback_udp()
    return run_process(functools.partial(join_sites, args))


if __name__ == '__main__':
    raise SystemExit(main())
