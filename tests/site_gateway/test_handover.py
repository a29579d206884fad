"""The remote gateway in its site's process: it hands a stream over in the tick of the node that
takes it there, and by a timer of its own only what no node takes so.

The operator is a Zenoh session of the test's, with the operator's certificate; the gateway and
the reading node share one executor, as in a site's process.
"""
import json
import socket
import time

from domains import session_domain_id
from geometry_msgs.msg import PoseStamped
import pytest
import rclpy
from rclpy.context import Context
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.task import Future
import zenoh

from haptic_util import intra_process
from haptic_util.cdr import MessageCodec
from haptic_util.tally import Tally
from site_gateway.certs import init_ca, issue
from site_gateway.gateway import GatewayNode, HANDOVER_LIMIT
from site_gateway.routes import site_routes
from site_gateway.zenoh_config import Credentials, session_config

PING, PONG = 'bench/ping', 'bench/pong'
POSE_TYPE = 'geometry_msgs/msg/PoseStamped'
POSE = MessageCodec(PoseStamped)
CONNECT_LIMIT = 20.0  # [s] for the operator's session to reach the gateway, on a busy machine


@pytest.fixture(scope='module')
def certs(tmp_path_factory):
    folder = tmp_path_factory.mktemp('certs')
    init_ca(folder)
    for role in ('remote', 'operator'):
        issue(folder, role)
    return folder


@pytest.fixture
def site(certs):
    """The remote gateway in a process of intra-process delivery, listening on loopback."""
    with socket.socket() as probe:
        probe.bind(('127.0.0.1', 0))
        endpoint = f'tls/127.0.0.1:{probe.getsockname()[1]}'
    context = Context()
    rclpy.init(context=context, domain_id=session_domain_id())
    intra_process.enable()
    gateway = GatewayNode(context=context, parameter_overrides=[
        Parameter('role', value='remote'), Parameter('listen', value=[endpoint]),
        Parameter('certs', value=str(certs)),
        Parameter('to_remote', value=[f'{PING}:{POSE_TYPE}']),
        Parameter('to_operator', value=[f'{PONG}:{POSE_TYPE}'])])
    routes = site_routes('operator', [f'{PING}:{POSE_TYPE}'], [f'{PONG}:{POSE_TYPE}'])
    operator = zenoh.open(zenoh.Config.from_json5(json.dumps(session_config(
        routes, listen=(), connect=(endpoint,),
        credentials=Credentials.of_site(certs, 'operator'), prefix='haptic'))))
    put = operator.declare_publisher(routes.outgoing[0].key('haptic')).put
    yield context, gateway, put
    operator.close()
    gateway.destroy_node()
    intra_process.close()
    rclpy.try_shutdown(context=context)


def ping(k: int) -> bytes:
    return POSE.encode((k, 0, 'world', 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0))


def spin(executor, seconds: float) -> None:
    executor.spin_until_future_complete(Future(), timeout_sec=seconds)


@pytest.mark.parametrize('in_tick', [True, False], ids=['in_its_tick', 'pushed'])
def test_a_stream_is_handed_over_in_the_tick_of_the_node_that_takes_it_there(site, in_tick):
    context, gateway, put = site
    got = []
    reader = Node('follower', context=context)
    pings = intra_process.link_subscription(reader, POSE, PING, got.append, refused=Tally(),
                                            in_tick=in_tick)
    executor = EventsExecutor(context=context)
    for node in (gateway, reader):
        executor.add_node(node)
    deadline = time.monotonic() + CONNECT_LIMIT
    tick = pings.take if in_tick else (lambda: None)  # the follower's tick, as far as it reads
    while not got and time.monotonic() < deadline:  # until a first ping crosses
        put(ping(-1))
        spin(executor, 0.05)
        tick()
    assert got, 'no ping crossed'
    spin(executor, 0.2)
    tick()
    got.clear()
    for k in range(3 * HANDOVER_LIMIT):
        put(ping(k))
    spin(executor, 0.5)  # the gateway's ticks, had it a timer for this stream
    if in_tick:
        assert got == []  # it waits in Zenoh for the follower's tick
        tick()
        assert [values[0] for values in got] == list(range(HANDOVER_LIMIT))
    else:
        assert [values[0] for values in got] == list(range(3 * HANDOVER_LIMIT))
    executor.shutdown()
    reader.destroy_node()
