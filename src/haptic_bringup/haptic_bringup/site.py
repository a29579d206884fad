"""One site of a telerobotic session, on its own machine: its nodes, its gateway, its recorder.

    haptic_site remote --listen tls/0.0.0.0:7447 --certs DIR [--scheme model] [--record DIR]
    haptic_site operator --connect tls/REMOTE_HOST:7447 --certs DIR [--scheme model]
        [--record DIR] [--experiment FILE] [--duration S] [--delay S] [--jitter S] [--loss P]

The operator's site runs the wand driver and the leader (one process), the remote site the robot
and the follower (one process; with ``--imaging``, the probe's imager in another), each in its own
DDS domain on its own machine, with local-only discovery; only the site's gateway
(``site_gateway``, a node of the site's process) talks to the other site, over one mutual-TLS
Zenoh connection. ``--certs`` is the folder of this
site's files from ``haptic_certs`` (``ca.pem``, ``<role>.pem``, ``<role>.key``); ``--insecure``
runs plaintext instead, and the gateway warns at every start. Both sites must run the same
``--scheme``.
``--delay``/``--jitter``/``--loss`` add the emulated link to what this site sends, on top of the
real network (none by default).

A site waits for its own nodes and gateway, then runs until Ctrl-C, the end of the operator's
experiment, or the other site stopping (its gateway says so, and this one's then ends its
process), and stops its processes. With ``--record DIR`` its process records itself into
``DIR/<role>``. A connection that is lost is waited for: the nodes' watchdogs keep the patient
safe meanwhile, and the session goes on when it returns. On a full ROS 2 install,
``operator_site.launch.py`` and ``remote_site.launch.py`` do the same.
"""
import argparse
import dataclasses
import os
import pathlib
import socket
from typing import Optional

import yaml

from haptic_bringup.launcher import (add_run_arguments, gateway_remap, link_parameters, Loop,
                                     LoopConfig, node_parameters, priority_parameters,
                                     site_nodes, teleop_endpoints)
from haptic_bringup.processes import run_until_stopped, start_child
from haptic_contract.graph import FRAME_TOPICS, RELIABLE_CROSSINGS, TO_OPERATOR, TO_REMOTE
from haptic_contract.teleop import Scheme, SCHEMES
from site_gateway.certs import init_ca, issue

__all__ = ['GATEWAY_MODULE', 'SiteConfig', 'Site', 'gateway_argv', 'gateway_parameters',
           'loopback_gateway_parameters', 'loopback_gateways', 'main', 'site_parameters']

GATEWAY_MODULE = 'site_gateway.gateway'
ROLES = ('operator', 'remote')


@dataclasses.dataclass
class SiteConfig:
    """One site: its role, how it reaches the other, and its session (nodes, domain, bag)."""

    role: str
    loop: LoopConfig
    listen: tuple = ()
    connect: tuple = ()
    certs: Optional[str] = None
    insecure: bool = False


def gateway_parameters(role: str, *, listen=(), connect=(), certs: Optional[str] = None,
                       insecure: bool = False, link: Optional[dict] = None) -> dict:
    """Return the parameters of ``role``'s gateway for the session's crossing topics."""
    return {'role': role, 'listen': list(listen) or [''], 'connect': list(connect) or [''],
            'certs': str(pathlib.Path(certs).expanduser().resolve()) if certs else '',
            'insecure': insecure, 'to_remote': list(TO_REMOTE),
            'to_operator': list(TO_OPERATOR), 'reliable': list(RELIABLE_CROSSINGS),
            'frames': list(FRAME_TOPICS), **(link or {})}


def site_parameters(site: SiteConfig) -> dict:
    """Every node's parameters of the site: as the local launcher's session, and the gateway.

    The recorder, if any, is in the site's process and writes its own bag (``DIR/<role>``).
    """
    merged = node_parameters(site.loop)
    merged[f'{site.role}_gateway'] = {'ros__parameters': {**gateway_parameters(
        site.role, listen=site.listen, connect=site.connect, certs=site.certs,
        insecure=site.insecure, link=site.loop.link), **priority_parameters(site.loop)}}
    return merged


def loopback_gateway_parameters(folder: pathlib.Path, *, link: Optional[dict] = None,
                                routes: Optional[dict] = None) -> dict:
    """Return both sites' gateway parameters for one machine, over loopback mutual TLS.

    The single-machine session takes the deployed path: a CA and both sites' certificates made
    for the run in ``folder/certs``, the remote gateway listening on a free loopback port, the
    operator's dialling it, each applying the emulated ``link`` to what it sends. ``routes``
    (``to_remote``, ``to_operator``, and ``reliable`` and ``frames`` if any) replace the
    session's crossings.
    """
    certs = folder / 'certs'
    init_ca(certs)
    for role in ROLES:
        issue(certs, role)
    with socket.socket() as probe:
        probe.bind(('127.0.0.1', 0))
        endpoint = [f'tls/127.0.0.1:{probe.getsockname()[1]}']
    replaced = {'reliable': [''], 'frames': [''], **routes} if routes else {}
    return {role: {**gateway_parameters(role, certs=str(certs), link=link, **{side: endpoint}),
                   **replaced}
            for role, side in (('remote', 'listen'), ('operator', 'connect'))}


def loopback_gateway_files(run_dir: pathlib.Path, *, link: Optional[dict] = None,
                           routes: Optional[dict] = None,
                           priority: Optional[dict] = None) -> dict:
    """Write both sites' gateway parameters for one machine; return role → parameters file.

    See ``loopback_gateway_parameters``. ``priority`` (``priority_parameters``) sets their
    ``thread_priority``, if it holds one.
    """
    files = {}
    for role, values in loopback_gateway_parameters(run_dir, link=link, routes=routes).items():
        files[role] = run_dir / f'{role}_gateway.yaml'
        files[role].write_text(yaml.safe_dump({f'{role}_gateway': {
            'ros__parameters': {**values, **(priority or {})}}}))
    return files


def loopback_gateways(files: dict, python: str, env: dict, remote_env: dict) -> list:
    """Start both sites' gateways, each a process of its own, from ``loopback_gateway_files``."""
    return [start_child(f'{role}_gateway', gateway_argv(python, role, files[role]), role_env)
            for role, role_env in (('remote', remote_env), ('operator', env))]


def gateway_argv(python: str, role: str, params: pathlib.Path) -> list:
    """Return the command line of ``role``'s gateway with the parameters file ``params``."""
    return [python, '-m', GATEWAY_MODULE, '--ros-args', '-r', f'__node:={role}_gateway',
            '--params-file', str(params)]


class Site(Loop):
    """Start one site, wait until its own part is up, and stop it cleanly (a context manager)."""

    def __init__(self, site: SiteConfig) -> None:
        super().__init__(site.loop)
        self.site = site

    def _parameters(self) -> dict:
        """Return the parameters file's content: this site's nodes' and its gateway's."""
        return site_parameters(self.site)

    def _start_children(self, env: dict, params: pathlib.Path) -> None:
        """Start this site's process (with its gateway), and its imager if it images."""
        site, config = self.site, self.config
        ros_args = ['--ros-args', '--params-file', str(params)]
        in_process = gateway_remap(site.role) if config.gateway_in_process else []
        self.children.append(start_child(
            site.role, self._composed(site_nodes(config, site.role), [*ros_args, *in_process]),
            env))
        if site.role == 'remote':
            self._start_imager(ros_args, env)
        if not config.gateway_in_process:
            self.children.append(start_child(
                'gateway', gateway_argv(config.python, site.role, params), env))

    def _wait_until_up(self) -> None:
        """Wait for this site's own endpoints: the other site may not be there yet."""
        operator, remote = teleop_endpoints(self.config).values()
        self._wait_for({self.config.domain_id: operator if self.site.role == 'operator'
                        else remote})

    def _domains(self) -> list:
        return [self.config.domain_id]


def parse_args(argv=None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(
        prog='haptic_site', description=__doc__.split('\n\n')[0],
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('role', choices=ROLES, help='which site this machine runs')
    parser.add_argument('--listen', action='append', default=[], metavar='ENDPOINT',
                        help='where the remote site listens, e.g. tls/0.0.0.0:7447')
    parser.add_argument('--connect', action='append', default=[], metavar='ENDPOINT',
                        help='the remote site the operator site dials, e.g. tls/HOST:7447')
    parser.add_argument('--certs', metavar='DIR', help="this site's files from haptic_certs")
    parser.add_argument('--insecure', action='store_true',
                        help='plaintext tcp/ endpoints, no certificates (warned at every start)')
    parser.add_argument('--scheme', choices=SCHEMES, default=Scheme.MODEL.value,
                        help='bilateral scheme, the same on both sites (default: model)')
    parser.add_argument('--experiment', help="operator: the operator's script (default: the "
                        'scripted scan)')
    parser.add_argument('--duration', type=float, default=0.0,
                        help="operator: stop after this many seconds (0: the script's length)")
    parser.add_argument('--record', metavar='DIR', help="record this site's bag to DIR")
    parser.add_argument('--delay', type=float, default=0.0,
                        help='emulated one-way delay added to what this site sends [s]')
    parser.add_argument('--jitter', type=float, default=0.0,
                        help='standard deviation of the emulated delay [s]')
    parser.add_argument('--loss', type=float, default=0.0,
                        help='probability that the emulated link loses a message')
    parser.add_argument('--delay-trace', metavar='CSV',
                        help='replay one-way delays from a CSV (time,delay in s)')
    parser.add_argument('--imaging', action='store_true',
                        help='remote: image the probe\'s view (operator: record it)')
    add_run_arguments(parser, run_dir='build/site')
    args = parser.parse_args(argv)
    if not (args.listen or args.connect):
        parser.error('give --listen (the remote site) or --connect (the operator site)')
    if not (args.certs or args.insecure):
        parser.error('give --certs DIR (see haptic_certs), or --insecure for plaintext')
    return args


def site_config(args: argparse.Namespace) -> SiteConfig:
    """Return the site the command line asks for."""
    loop = LoopConfig(composed=True, teleop=args.scheme, domain_id=args.domain_id,
                      experiment=args.experiment, duration=args.duration, record=args.record,
                      params_file=args.params_file, run_dir=pathlib.Path(args.run_dir),
                      link=link_parameters(args), imaging=args.imaging)
    return SiteConfig(args.role, loop, tuple(args.listen), tuple(args.connect), args.certs,
                      args.insecure)


def main(argv=None) -> int:
    args = parse_args(argv)
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    site = Site(site_config(args))
    peer = 'listening on ' + ', '.join(args.listen) if args.listen else \
        'connecting to ' + ', '.join(args.connect)

    def why(ended) -> str:
        """Say why the site stopped: its process ends by itself (0) only when its session does."""
        if ended is None:
            return 'stopped'
        if ended.returncode != 0 or ended.name != args.role:
            return f'{ended.name} exited'
        return 'the experiment ended, or the other site stopped' if args.role == 'operator' \
            else 'the other site stopped'

    return run_until_stopped(
        site, 'haptic_site', lambda: f'{args.role} site up in {site.startup_time:.2f} s (domain '
        f'{args.domain_id}, {args.scheme}; {peer}); Ctrl-C stops', why=why)


if __name__ == '__main__':
    raise SystemExit(main())
