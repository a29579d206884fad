"""The gateway's Zenoh configuration: endpoints, mutual TLS, access control, publishers.

The access control is judged by an evaluator written here from Zenoh's documented semantics
(deny by default; a message passes when a policy joins a subject matching the peer's certificate
common name to a rule of its message kind, flow and a key expression that includes its key),
not by reading the rules back; ``tests/integration/test_site_gateway.py`` checks Zenoh itself.
"""
import json
import os

import pytest
import zenoh

from site_gateway.certs import init_ca, issue
from site_gateway.routes import ROLES, site_routes
from site_gateway.zenoh_config import (access_control, check_endpoints, Credentials,
                                       publisher_options, session_config)

COMMAND = '/teleop/command:haptic_msgs/msg/TeleopCommand'
FEEDBACK = '/teleop/feedback:haptic_msgs/msg/TeleopFeedback'


def _chunk_match(pattern: list, key: list) -> bool:
    """Whether key expression ``pattern`` (chunks, with * and **) includes ``key``."""
    if not pattern:
        return not key
    if pattern[0] == '**':
        return any(_chunk_match(pattern[1:], key[i:]) for i in range(len(key) + 1))
    return bool(key) and pattern[0] in ('*', key[0]) and _chunk_match(pattern[1:], key[1:])


def allowed(acl: dict, common_name, message: str, flow: str, key: str) -> bool:
    subjects = {s['id'] for s in acl['subjects'] if common_name in s['cert_common_names']}
    rules = {r['id']: r for r in acl['rules']}
    for policy in acl['policies']:
        if not subjects & set(policy['subjects']):
            continue
        for rule in (rules[name] for name in policy['rules']):
            if (message in rule['messages'] and flow in rule['flows']
                    and any(_chunk_match(k.split('/'), key.split('/'))
                            for k in rule['key_exprs'])):
                return rule['permission'] == 'allow'
    return acl['default_permission'] == 'allow'


def test_only_the_operator_certificate_puts_commands_at_the_remote_site():
    acl = access_control('remote', 'haptic')
    command = 'haptic/operator/teleop/command'
    assert allowed(acl, 'operator', 'put', 'ingress', command)
    for stranger in ('remote', 'stranger', None):
        assert not allowed(acl, stranger, 'put', 'ingress', command)
    # The remote role puts under its own keys: that reaches the gateway, which refuses it.
    assert allowed(acl, 'remote', 'put', 'ingress', 'haptic/remote/teleop/command')
    assert not allowed(acl, 'stranger', 'put', 'ingress', 'haptic/stranger/teleop/command')
    assert not allowed(acl, 'operator', 'put', 'ingress', 'other/operator/teleop/command')


def test_only_the_other_site_is_sent_this_site_s_messages():
    acl = access_control('remote', 'haptic')
    feedback = 'haptic/remote/teleop/feedback'
    assert allowed(acl, 'operator', 'put', 'egress', feedback)
    assert not allowed(acl, 'remote', 'put', 'egress', feedback)
    assert not allowed(acl, None, 'put', 'egress', feedback)
    operator = access_control('operator', 'haptic')
    assert allowed(operator, 'remote', 'put', 'ingress', feedback)
    assert not allowed(operator, 'operator', 'put', 'ingress', feedback)
    assert allowed(operator, 'remote', 'put', 'egress', 'haptic/operator/teleop/command')
    assert not allowed(operator, 'remote', 'query', 'ingress', feedback)


def test_subscriptions_are_taken_from_each_role_only():
    acl = access_control('remote', 'haptic')
    for role in ROLES:
        assert allowed(acl, role, 'declare_subscriber', 'ingress', 'haptic/remote/teleop/x')
        assert allowed(acl, role, 'declare_subscriber', 'egress', 'haptic/*/teleop/command')
    assert not allowed(acl, 'stranger', 'declare_subscriber', 'ingress', 'haptic/remote/a')


@pytest.fixture(scope='module')
def credentials(tmp_path_factory):
    folder = tmp_path_factory.mktemp('certs')
    init_ca(folder)
    issue(folder, 'remote')
    return Credentials.of_site(folder, 'remote')


def test_the_secure_session_is_mutual_tls_with_access_control_and_opens(credentials):
    routes = site_routes('remote', [COMMAND], [FEEDBACK])
    config = session_config(routes, listen=['tls/127.0.0.1:0'], connect=[],
                            credentials=credentials, prefix='haptic', lease=1.0)
    tls = config['transport']['link']['tls']
    assert tls['enable_mtls'] is True and tls['verify_name_on_connect'] is True
    assert tls['root_ca_certificate'] == str(credentials.ca)
    assert tls['listen_private_key'] == tls['connect_private_key'] == str(credentials.key)
    assert config['access_control']['default_permission'] == 'deny'
    assert config['scouting']['multicast']['enabled'] is False
    assert config['transport']['link']['tx']['lease'] == 1000
    session = zenoh.open(zenoh.Config.from_json5(json.dumps(config)))  # Zenoh takes it
    session.close()


def test_plaintext_has_no_tls_and_no_access_control():
    routes = site_routes('operator', [COMMAND], [FEEDBACK])
    config = session_config(routes, listen=[], connect=['tcp/127.0.0.1:7447'],
                            credentials=None, prefix='haptic')
    assert 'tls' not in config['transport']['link'] and 'access_control' not in config


@pytest.mark.parametrize('listen, connect, insecure, words', [
    ([], [], False, ['listen', 'connect']),
    (['tcp/0.0.0.0:7447'], [], False, ['tcp', '--insecure']),
    ([], ['tls/host:7447'], True, ['tls', "['tcp', 'udp']"]),
    ([], ['tls/host'], False, ['proto/host:port']),
    ([], ['host:7447'], False, ['proto/host:port']),
    (['ws/0.0.0.0:7447'], [], False, ["'ws'"]),
])
def test_endpoints_are_checked(listen, connect, insecure, words):
    with pytest.raises(ValueError) as error:
        check_endpoints(listen, connect, insecure=insecure)
    for word in words:
        assert word in str(error.value)


def test_good_endpoints_pass():
    check_endpoints(['tls/0.0.0.0:7447'], ['quic/[::1]:7447'], insecure=False)
    check_endpoints([], ['tcp/127.0.0.1:7447'], insecure=True)


def test_a_key_readable_by_others_or_a_missing_file_is_refused(credentials, tmp_path):
    os.chmod(credentials.key, 0o644)
    try:
        with pytest.raises(ValueError, match='chmod 600'):
            credentials.check()
    finally:
        os.chmod(credentials.key, 0o600)
    with pytest.raises(ValueError, match='operator.pem is missing'):
        Credentials.of_site(credentials.ca.parent, 'operator')


def test_streams_drop_and_are_batched_what_must_arrive_blocks_frames_go_last():
    stream, reliable = publisher_options('stream'), publisher_options('reliable')
    assert not stream['express'] and stream['priority'] == zenoh.Priority.REAL_TIME
    assert stream['congestion_control'] == zenoh.CongestionControl.DROP
    assert reliable['congestion_control'] == zenoh.CongestionControl.BLOCK
    assert reliable['reliability'] == zenoh.Reliability.RELIABLE
    frame = publisher_options('frame')  # an image: after both, and dropped rather than waited
    assert frame['priority'] == zenoh.Priority.DATA
    assert frame['congestion_control'] == zenoh.CongestionControl.DROP
    with pytest.raises(ValueError):
        publisher_options('sometimes')
