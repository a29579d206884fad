"""Two site gateways as real processes on loopback, mutual TLS between them, attacked.

The test process joins both sites' DDS domains (``two_sites.Sites``) and stands in for
both sites' nodes; it also opens Zenoh sessions of its own as the peers a hospital network may
hold: one with a certificate of another CA, one without a certificate, one in plaintext, one with
a valid certificate of the wrong role, and one with the operator's certificate that floods. What
the gateways did is read from outside: what arrived in each domain, the remote gateway's reports
on its ``/diagnostics``, and its log.
"""
import json
import os
import pathlib
import signal
import socket
import subprocess
import sys
import time

from diagnostic_msgs.msg import DiagnosticArray
from domains import session_domain_id
from geometry_msgs.msg import PoseStamped
import numpy as np
import psutil
import pytest
from rclpy.serialization import serialize_message
from two_sites import connect, POSE, Sites, TO_OPERATOR, TO_REMOTE
import yaml
import zenoh

from haptic_bringup.launcher import loop_environment
from haptic_bringup.processes import Child, stop_children
from haptic_util.qos import HAPTIC_STREAM_QOS
from site_gateway.certs import init_ca, issue

FORGED = -7.0  # pose x of what the test's own peers put
AFTER = 1e6  # pose x from which the poses are published after a link's return
LEASE = 1.0  # [s] the gateways' default
RESUME_LIMIT = 2.0  # [s] from the link's return to the session going on
PEER_WAIT = 20.0  # [s] for a gateway to start and its peer to connect, on a busy machine


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(('127.0.0.1', 0))
        return probe.getsockname()[1]


def start_gateway(folder: pathlib.Path, role: str, domain: int, **parameters) -> Child:
    """Start ``role``'s gateway in ``domain``, its output to ``folder/<role>.log``."""
    values = {'role': role, 'to_remote': [f'{TO_REMOTE}:{POSE}'],
              'to_operator': [f'{TO_OPERATOR}:{POSE}'], **parameters}
    params = folder / f'{role}_gateway.yaml'
    params.write_text(yaml.safe_dump({f'{role}_gateway': {'ros__parameters': values}}))
    argv = [sys.executable, '-m', 'site_gateway.gateway', '--ros-args', '-r',
            f'__node:={role}_gateway', '--params-file', str(params)]
    env = loop_environment(domain, folder / 'log')
    with open(folder / f'{role}.log', 'ab') as log:
        process = subprocess.Popen(argv, env=env, stdout=log, stderr=subprocess.STDOUT,
                                   start_new_session=True)
    return Child(f'{role}_gateway', process, argv, env)


class Watched(Sites):
    """Both sites, and the gateways' reports as they come."""

    def __init__(self, operator: int, remote: int) -> None:
        super().__init__(operator, remote)
        self.reports = []  # (time, {key: value}) of the remote gateway
        self.operator_reports = []  # {key: value} of the operator gateway
        for node in self.nodes:
            node.create_subscription(DiagnosticArray, '/diagnostics', self._on_gateway, 10)

    def _on_gateway(self, array: DiagnosticArray) -> None:
        for status in array.status:
            values = {value.key: value.value for value in status.values}
            if status.name == '/remote_gateway':
                self.reports.append((time.monotonic(), values))
            elif status.name == '/operator_gateway':
                self.operator_reports.append(values)

    def latest(self, key: str, default: str = '0') -> str:
        return self.reports[-1][1].get(key, default) if self.reports else default

    def next_report(self) -> dict:
        """Wait for a report of the remote gateway made from now on; return it."""
        return self.next_reports()[0]

    def next_reports(self) -> tuple:
        """Wait for a report of each gateway made from now on; return (remote, operator)."""
        counts = len(self.reports), len(self.operator_reports)
        deadline = time.monotonic() + PEER_WAIT
        while ((len(self.reports) < counts[0] + 2 or len(self.operator_reports) < counts[1] + 2)
               and time.monotonic() < deadline):
            self.spin(0.05)  # the second: one already being published may predate now
        assert len(self.reports) >= counts[0] + 2, 'the remote gateway stopped reporting'
        assert len(self.operator_reports) >= counts[1] + 2, \
            'the operator gateway stopped reporting'
        return self.reports[-1][1], self.operator_reports[-1]


@pytest.fixture(scope='module')
def site(tmp_path_factory):
    """The two gateways (the remote one listening on loopback) and the test's sides of both."""
    folder = tmp_path_factory.mktemp('gateways')
    certs, other_ca = folder / 'certs', folder / 'other_ca'
    init_ca(certs)
    for role in ('remote', 'operator'):
        issue(certs, role)
    init_ca(other_ca)
    issue(other_ca, 'operator')
    operator_domain, remote_domain = session_domain_id(), session_domain_id(second=True)
    endpoint = f'tls/127.0.0.1:{free_port()}'
    remote = start_gateway(folder, 'remote', remote_domain, listen=[endpoint], certs=str(certs))
    operator = start_gateway(folder, 'operator', operator_domain, connect=[endpoint],
                             certs=str(certs))
    sites = Watched(operator_domain, remote_domain)
    gateways = {'remote': remote, 'operator': operator}
    yield {'sites': sites, 'folder': folder, 'certs': certs, 'other_ca': other_ca,
           'endpoint': endpoint, 'gateways': gateways}
    sites.close()
    assert set(stop_children(list(gateways.values())).values()) == {0}


def streams(sites: Sites) -> tuple:
    """Listen and publish both ways; return (publish out, arrivals out, publish back, back)."""
    if (1, TO_REMOTE) not in sites.received:
        sites.listen(1, TO_REMOTE)
        sites.listen(0, TO_OPERATOR)
        sites.publishers = sites.publisher(0, TO_REMOTE), sites.publisher(1, TO_OPERATOR)
    return (sites.publishers[0], sites.received[(1, TO_REMOTE)], sites.publishers[1],
            sites.received[(0, TO_OPERATOR)])


def zenoh_peer(site: dict, folder: pathlib.Path | None, role: str | None, *,
               mode: str = 'peer', plaintext: bool = False) -> zenoh.Session:
    """Open a Zenoh session to the remote gateway with ``role``'s files in ``folder``.

    ``folder`` None: no certificate.
    """
    endpoint = site['endpoint'].replace('tls/', 'tcp/') if plaintext else site['endpoint']
    config = {'mode': mode, 'connect': {'endpoints': [endpoint]}, 'listen': {'endpoints': []},
              'scouting': {'multicast': {'enabled': False}, 'gossip': {'enabled': False}}}
    if not plaintext:
        tls = {'root_ca_certificate': str(site['certs'] / 'ca.pem'),
               'verify_name_on_connect': False, 'enable_mtls': folder is not None}
        if folder is not None:
            for side in ('listen', 'connect'):
                tls[f'{side}_certificate'] = str(folder / f'{role}.pem')
                tls[f'{side}_private_key'] = str(folder / f'{role}.key')
        config['transport'] = {'link': {'tls': tls}}
    return zenoh.open(zenoh.Config.from_json5(json.dumps(config)))


def forged_pose() -> bytes:
    message = PoseStamped()
    message.pose.position.x = FORGED
    return serialize_message(message)


def test_poses_cross_both_ways_in_order_over_mutual_tls(site):
    sites = site['sites']
    publish_out, out, publish_back, back = streams(sites)
    connect(sites, [(publish_out, out), (publish_back, back)])
    # The counts from here: the warm-up's first poses may be put before the far gateway's
    # subscription has reached the near one, and go nowhere. Counted from the start, two CI
    # runs read 101 received against 104 put, both times.
    before = sites.next_reports()
    count = 1000
    sites.run([(publish_out, 1), (publish_back, 10)], count, 1e-3)  # 1 kHz out, 100 Hz back
    sites.spin(0.3)
    after = sites.next_reports()  # both gateways' counts are final

    def counted(key: str, site: int) -> int:
        return int(after[site][key]) - int(before[site][key])
    put, relayed = counted('out relayed', 1), counted('out relayed', 0)
    xs, delays = np.array(out).T
    back_xs = np.array(back)[:, 0]
    p50, p99 = np.percentile(delays, [50, 99])
    print(f'\n{len(xs)} of {count} out, {len(back_xs)} of {count // 10} back; one way through '
          f'both gateways p50 {p50 * 1e3:.2f} ms, p99 {p99 * 1e3:.2f} ms; the operator '
          f'gateway put {put}, the remote one received {counted(f"in {TO_REMOTE} received", 0)}')
    # Between the gateways nothing is lost. The DDS hops at each end are best effort at 1 kHz
    # with the haptic depth of 10: how many they drop is the machine's load (36 of 1000 at load
    # 17), not a property of the gateways.
    assert counted(f'in {TO_REMOTE} received', 0) == put > 0
    assert counted(f'in {TO_OPERATOR} received', 1) == relayed > 0
    assert 0 < len(xs) <= put and 0 < len(back_xs) <= relayed
    assert np.all(np.diff(xs) > 0) and np.all(np.diff(back_xs) > 0)
    log = (site['folder'] / 'remote.log').read_text()
    assert "mutual TLS as 'remote'" in log and 'connected: tls/' in log


@pytest.mark.parametrize('peer, refusal', [
    ('another CA', 'invalid peer certificate'),
    ('no certificate', 'peer sent no certificates'),
    ('plaintext', 'InvalidContentType'),
])
def test_a_peer_of_another_ca_without_certificate_or_in_plaintext_is_refused_and_logged(
        site, peer, refusal):
    folder = {'another CA': site['other_ca'], 'no certificate': None,
              'plaintext': None}[peer]
    log = site['folder'] / 'remote.log'
    before = log.read_text().count(refusal)
    with pytest.raises(zenoh.ZError):  # a client gives up at once when it is refused
        zenoh_peer(site, folder, 'operator', mode='client', plaintext=peer == 'plaintext')
    deadline = time.monotonic() + 5.0
    while log.read_text().count(refusal) == before and time.monotonic() < deadline:
        time.sleep(0.05)
    assert log.read_text().count(refusal) > before, f'the refusal was not logged: {refusal}'


def test_a_valid_certificate_of_the_wrong_role_publishes_commands_and_none_is_delivered(site):
    sites = site['sites']
    publish_out, out, publish_back, back = streams(sites)
    connect(sites, [(publish_out, out), (publish_back, back)])
    stranger = zenoh_peer(site, site['certs'], 'remote')  # a remote site's own certificate
    heard = []
    stranger.declare_subscriber(f'haptic/*/{TO_OPERATOR}',  # the remote site's stream
                                lambda sample: heard.append(str(sample.key_expr)))
    data, sent = forged_pose(), 0
    try:
        deadline = time.monotonic() + PEER_WAIT
        while not stranger.info.peers_zid() and time.monotonic() < deadline:
            time.sleep(0.05)
        assert stranger.info.peers_zid(), 'the wrong role\'s peer never connected'
        for _ in range(200):  # as the operator, then under its own role's keys
            for role in ('operator', 'remote'):
                stranger.put(f'haptic/{role}/{TO_REMOTE}', data)
                sent += 1
            publish_back(1.0)  # the remote site's stream goes on meanwhile
            sites.spin(0.005)
        report = sites.next_report()
    finally:
        stranger.close()
    assert FORGED not in [x for x, _ in out], 'a forged command was delivered'
    assert int(report[f'refused: {TO_REMOTE} from the remote role']) >= 1
    assert f'{TO_REMOTE} from the remote role' in (site['folder'] / 'remote.log').read_text()
    assert not heard, f'the wrong role was sent {set(heard)}'


def test_malformed_bytes_on_a_key_are_dropped_counted_and_the_link_goes_on(site):
    sites = site['sites']
    publish_out, out, publish_back, back = streams(sites)
    connect(sites, [(publish_out, out), (publish_back, back)])
    raw = sites.nodes[0].create_publisher(PoseStamped, TO_REMOTE, HAPTIC_STREAM_QOS)
    before = int(sites.latest(f'refused: malformed {TO_REMOTE}'))
    garbage = [b'\x00\x01\x00\x00' + bytes(8) + (1000 + k).to_bytes(4, 'little') + b'map'
               for k in range(100)]
    for data in garbage:  # the operator site's DDS carries anything; its gateway forwards it
        raw.publish(data)
        sites.spin(0.002)
    out.clear()
    sites.run([(publish_out, 1)], 200, 1e-3)
    report = sites.next_report()
    assert int(report[f'refused: malformed {TO_REMOTE}']) - before >= 90  # DDS may drop some
    assert len(out) >= 190, 'the link did not go on after the malformed bytes'


def test_a_flood_from_an_authenticated_peer_is_shed_and_the_gateway_goes_on(site):
    """A holder of the operator's certificate puts 20 kHz for 1 s.

    The remote gateway hands on at most its ``max_rate`` (2 kHz), keeps reporting, and carries
    the operator's stream after.
    """
    sites = site['sites']
    publish_out, out, publish_back, back = streams(sites)
    connect(sites, [(publish_out, out), (publish_back, back)])
    flooder = zenoh_peer(site, site['certs'], 'operator')
    publisher = flooder.declare_publisher(f'haptic/operator/{TO_REMOTE}', express=True)
    data, sent = forged_pose(), 0
    try:
        deadline = time.monotonic() + PEER_WAIT
        while not flooder.info.peers_zid() and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(0.3)  # the remote gateway's subscription has reached the flooder
        delivered_before = int(sites.next_report()[f'in {TO_REMOTE} delivered'])
        start = time.monotonic()
        while time.monotonic() - start < 1.0:
            publisher.put(data)
            sent += 1
            lag = start + sent / 20_000 - time.monotonic()
            if lag > 0:
                time.sleep(lag)
        elapsed = time.monotonic() - start
    finally:
        flooder.close()
    report = sites.next_report()
    delivered = int(report[f'in {TO_REMOTE} delivered']) - delivered_before
    shed = int(report.get(f'refused: {TO_REMOTE} over max_rate', '0'))
    print(f'\nflood: {sent} put in {elapsed:.2f} s, {delivered} handed on, {shed} shed')
    assert sent > 10_000  # it was a flood, even on a busy machine
    assert delivered <= 2000 * (elapsed + 1.5) + 100  # the rate, and a report period's slack
    assert shed > 0
    out.clear()
    sites.run([(publish_out, 1)], 200, 1e-3)
    sites.spin(0.2)
    assert len([x for x, _ in out if x != FORGED]) >= 190


def test_a_link_lost_for_longer_than_the_lease_comes_back_by_itself(site):
    """The operator's gateway frozen for 3 s, then running again: the streams go on.

    The remote gateway closes the session after its lease; the operator's opens it anew.
    """
    sites = site['sites']
    publish_out, out, publish_back, back = streams(sites)
    connect(sites, [(publish_out, out), (publish_back, back)])
    gateway = site['gateways']['operator']
    gateway.signal(signal.SIGSTOP)
    sites.run([(publish_out, 1)], 3000, 1e-3)
    out.clear()
    gateway.signal(signal.SIGCONT)
    returned = time.monotonic()
    first = None
    tick = 0
    while first is None and time.monotonic() - returned < 3 * RESUME_LIMIT:
        publish_out(AFTER + tick)  # told apart from what the frozen gateway's reader held
        tick += 1
        sites.spin(0.001)
        if any(x >= AFTER for x, _ in out):
            first = time.monotonic() - returned
    log = (site['folder'] / 'remote.log').read_text()
    print(f'\nthe session went on {first} s after the gateway ran again')
    assert 'connection lost' in log
    assert first is not None and first <= RESUME_LIMIT


def test_plaintext_needs_insecure_and_warns_at_every_start(tmp_path):
    domain = session_domain_id()
    refused = start_gateway(tmp_path, 'remote', domain, listen=['tcp/127.0.0.1:0'],
                            certs=str(tmp_path))
    assert refused.process.wait(60) == 2
    assert '--insecure' in (tmp_path / 'remote.log').read_text()
    for start in (1, 2):
        insecure = start_gateway(tmp_path, 'operator', domain, connect=['tcp/127.0.0.1:9'],
                                 insecure=True)
        deadline = time.monotonic() + PEER_WAIT
        while (tmp_path / 'operator.log').read_text().count('INSECURE plaintext') < start:
            assert time.monotonic() < deadline and insecure.returncode is None
            time.sleep(0.1)
        assert stop_children([insecure]) == {'operator_gateway': 0}
    assert (tmp_path / 'operator.log').read_text().count('INSECURE: plaintext') == 2
    assert not os.path.exists(tmp_path / 'ca.pem')


def test_a_gateway_is_a_udp_peer_on_loopback_and_shares_no_memory_with_its_site(site):
    """A gateway stands for the network: its site must not share memory with it, or a stopped
    gateway (a link down) stalls the site's own writes (``haptic_util.transport`` says how)."""
    streams(site['sites'])
    for name, gateway in site['gateways'].items():
        process = psutil.Process(gateway.pid)
        maps = pathlib.Path(f'/proc/{gateway.pid}/maps').read_text()
        assert '/dev/shm/fastrtps' not in maps, f'the {name} gateway maps Fast DDS memory'
        udp = {connection.laddr.ip for connection in process.net_connections(kind='udp')}
        assert udp == {'127.0.0.1'}, (name, udp)
