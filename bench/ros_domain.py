"""A ROS benchmark's DDS domain: its own, and discovery kept on this machine.

Benchmarks share the machine with the tests and with each other, so each takes ``--domain-id``
(default: ``ROS_DOMAIN_ID``, else the launcher's) and never discovers beyond the loopback.
"""

import os

from haptic_bringup.launcher import add_venv_prefix, DEFAULT_DOMAIN_ID

__all__ = ['add_option', 'keep_local']


def add_option(parser, help: str | None = None) -> None:
    """Add ``--domain-id N`` to a benchmark's command line."""
    parser.add_argument('--domain-id', type=int,
                        default=int(os.environ.get('ROS_DOMAIN_ID', DEFAULT_DOMAIN_ID)),
                        help=help)


def keep_local() -> None:
    """Make this interpreter's ROS 2 findable, and its discovery (and its children's) local."""
    add_venv_prefix()
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
