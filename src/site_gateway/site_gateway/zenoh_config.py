"""The Zenoh session of a site's gateway: transport, mutual TLS, access control, publishers.

Why these settings (``../shared/zenoh-link.md``):
- Peer mode, no multicast scouting nor gossip: the gateway talks to the endpoints it is given
  and to nothing else, so a hospital network needs one TCP port and no multicast. The remote
  site listens, the operator's connects; a connection that drops is tried again every
  ``RETRY`` s at most, forever, so the session comes back by itself.
- A lease of 1 s (keep-alives every 0.25 s): a link that is silent that long is closed and
  opened anew, rather than waited on for TCP's back-off, which after a cut of a few seconds
  resumes seconds after the network is back.
- Mutual TLS by default: each site shows a certificate of the sites' CA (``certs``), and the
  connecting site checks that the listening one's names the host it dialled.
- Access control denies by default. A certificate's common name is its role; each role may
  put under its own role's keys only (``routes``), and only the other site is sent this
  site's messages. Subscriptions are announced to every role, so that a site's gateway sees,
  logs and refuses what a certificate of the wrong role publishes where it may.
- Streams go at real-time priority, and are dropped when the link is congested: a late pose is
  worthless, and a blocked publisher would stall the DDS callback that feeds it. What must
  arrive is reliable and blocks. A message waits in a batch of its priority's queue until it is
  written, and a full queue drops it: with Zenoh's default of 2 batches, a sender descheduled
  for 2 ms lost messages (0.5-3.3 % of a 1 kHz stream over 10 s here at load 16, none with 16).
- Streams are not ``express``: Zenoh writes a message at once when the link is free, and joins
  in one batch only what piles up behind a write. Express, each message took a batch of its own,
  and a gateway that had been descheduled handed Zenoh more than 16 at once: with a core hogged,
  9 runs of ``test_poses_cross_both_ways_in_order_over_mutual_tls`` alternated with batched
  ones, one lost 38 of 1000 between the gateways (a CI run lost 12), and ``bench_link`` lost
  17-610 of 15000 pings in each of 5 runs; batched, none in 9, and none in 4 of 5 (217 in the
  fifth), the one-way p99 3.8-23 ms (median 5.0) against 1.9-86 ms (median 15.7), the p50 no
  slower. (rmw_zenoh's issue 314 saw 1 kHz topics lose rate under Zenoh's default batching;
  here, with zenoh 1.10, none did.)
- Frames (the probe's image, 64 kB at 30 Hz) go at data priority, below the streams and what
  must arrive: Zenoh sends a higher priority's batches first, so an image being written never
  holds a stream back. Dropped when congested, as a late image is worthless too.
"""
from dataclasses import dataclass
import os
from pathlib import Path
import stat

import zenoh

from site_gateway.routes import FRAME, RELIABLE, ROLES, SiteRoutes, STREAM

__all__ = ['Credentials', 'LEASE', 'RETRY', 'access_control', 'check_endpoints',
           'publisher_options', 'session_config']

LEASE = 1.0  # [s]
KEEP_ALIVES_PER_LEASE = 4
RETRY = (0.1, 0.5)  # [s] first and longest wait between tries to connect
QUEUE_BATCHES = 16  # per priority; Zenoh's most (its default, 2, dropped messages)
SECURE = ('tls', 'quic')  # transports with mutual TLS
PLAIN = ('tcp', 'udp')  # what --insecure allows instead


@dataclass(frozen=True)
class Credentials:
    """The files of one site's identity: the CA's certificate, its own and its private key."""

    ca: Path
    certificate: Path
    key: Path

    @classmethod
    def of_site(cls, directory, role: str) -> 'Credentials':
        """Return the files ``haptic_certs`` wrote for ``role`` in ``directory``, checked."""
        directory = Path(directory).expanduser()
        credentials = cls(directory / 'ca.pem', directory / f'{role}.pem',
                          directory / f'{role}.key')
        credentials.check()
        return credentials

    def check(self) -> None:
        """Raise ValueError if a file is missing or the key is readable by others."""
        for path in (self.ca, self.certificate, self.key):
            if not path.is_file():
                raise ValueError(f'{path} is missing (make it with haptic_certs, see README: '
                                 f'"Two machines, step by step")')
        mode = stat.S_IMODE(os.stat(self.key).st_mode)
        if mode & 0o077:
            raise ValueError(f'{self.key} is readable by others (mode {mode:o}); a private key '
                             f'must be its owner\'s only: chmod 600 {self.key}')


def check_endpoints(listen, connect, *, insecure: bool) -> None:
    """Raise ValueError unless each endpoint is ``proto/host:port`` of an allowed transport.

    Without ``insecure`` only TLS and QUIC (mutual TLS) are allowed; with it, only plain TCP
    and UDP, so that nobody believes a plaintext session to be protected by certificates.
    """
    allowed = PLAIN if insecure else SECURE
    if not listen and not connect:
        raise ValueError('give endpoints to listen on (the remote site) or to connect to '
                         '(the operator site)')
    for endpoint in (*listen, *connect):
        protocol, slash, address = endpoint.partition('/')
        host, colon, port = address.rpartition(':')
        if not slash or not colon or not host or not port.isdigit():
            raise ValueError(f'endpoint {endpoint!r} is not of the form proto/host:port')
        if protocol not in allowed:
            hint = (' (plaintext needs --insecure / insecure:=true)' if protocol in PLAIN
                    else '')
            raise ValueError(f'endpoint {endpoint!r}: transport {protocol!r} is not one of '
                             f'{list(allowed)}{hint}')


def session_config(routes: SiteRoutes, *, listen, connect, credentials: Credentials | None,
                   prefix: str, lease: float = LEASE, verify_name: bool = True) -> dict:
    """Return the Zenoh configuration of ``routes.role``'s gateway.

    ``credentials`` None is plaintext, without access control: no peer can be told from another.
    """
    retry = {'period_init_ms': round(RETRY[0] * 1e3), 'period_max_ms': round(RETRY[1] * 1e3),
             'period_increase_factor': 2}
    config = {
        'mode': 'peer',
        'listen': {'endpoints': list(listen)},
        'connect': {'endpoints': list(connect), 'timeout_ms': -1, 'exit_on_failure': False,
                    'retry': retry},
        'scouting': {'multicast': {'enabled': False}, 'gossip': {'enabled': False}},
        'timestamping': {'enabled': False},
        'transport': {'link': {'tx': {'lease': round(lease * 1e3),
                                      'keep_alive': KEEP_ALIVES_PER_LEASE,
                                      'queue': {'size': {'real_time': QUEUE_BATCHES,
                                                         'interactive_high': QUEUE_BATCHES,
                                                         'data': QUEUE_BATCHES}}}}},
    }
    if credentials is not None:
        files = {'root_ca_certificate': credentials.ca,
                 'listen_certificate': credentials.certificate,
                 'listen_private_key': credentials.key,
                 'connect_certificate': credentials.certificate,
                 'connect_private_key': credentials.key}
        config['transport']['link']['tls'] = {
            **{name: str(path) for name, path in files.items()},
            'enable_mtls': True, 'verify_name_on_connect': verify_name}
        config['access_control'] = access_control(routes.role, prefix)
    return config


def access_control(role: str, prefix: str) -> dict:
    """Deny by default; each certificate common name (a role) puts under its own keys only.

    ``role``'s messages go to the other role's certificate only. Every role's subscriptions
    are taken, so that a wrong role's put under its own keys reaches the gateway and is
    refused there by name (``routes``).
    """
    peer = ROLES[1 - ROLES.index(role)]
    rules = [{'id': 'subscriptions', 'messages': ['declare_subscriber'],
              'flows': ['ingress', 'egress'], 'permission': 'allow',
              'key_exprs': [f'{prefix}/**']},
             {'id': 'to_peer', 'messages': ['put'], 'flows': ['egress'], 'permission': 'allow',
              'key_exprs': [f'{prefix}/{role}/**']}]
    rules += [{'id': f'from_{name}', 'messages': ['put'], 'flows': ['ingress'],
               'permission': 'allow', 'key_exprs': [f'{prefix}/{name}/**']} for name in ROLES]
    subjects = [{'id': name, 'cert_common_names': [name]} for name in ROLES]
    policies = [{'rules': ['subscriptions', f'from_{name}'], 'subjects': [name]}
                for name in ROLES]
    policies.append({'rules': ['to_peer'], 'subjects': [peer]})
    return {'enabled': True, 'default_permission': 'deny', 'rules': rules,
            'subjects': subjects, 'policies': policies}


def publisher_options(kind: str) -> dict:
    """Return the ``declare_publisher`` options of a crossing's kind (STREAM, RELIABLE, FRAME)."""
    if kind == STREAM:
        return {'express': False, 'priority': zenoh.Priority.REAL_TIME,
                'congestion_control': zenoh.CongestionControl.DROP,
                'reliability': zenoh.Reliability.BEST_EFFORT}
    if kind == RELIABLE:
        return {'express': True, 'priority': zenoh.Priority.INTERACTIVE_HIGH,
                'congestion_control': zenoh.CongestionControl.BLOCK,
                'reliability': zenoh.Reliability.RELIABLE}
    if kind == FRAME:
        return {'express': True, 'priority': zenoh.Priority.DATA,
                'congestion_control': zenoh.CongestionControl.DROP,
                'reliability': zenoh.Reliability.BEST_EFFORT}
    raise ValueError(f'kind {kind!r} is not one of {[STREAM, RELIABLE, FRAME]}')
